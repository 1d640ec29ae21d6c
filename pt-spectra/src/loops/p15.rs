//! The 2-loop propagator term P15 from a cosmology-independent angular table.
//!
//! P15_X(k) = 15 P(k) ∫d³q₁d³q₂/(2π)⁶ X_5^s(k, q₁, −q₁, q₂, −q₂) P(q₁) P(q₂), X ∈ {F, G}. The kernel is
//! homogeneous of degree 0, so with r_i = q_i/k and the angular average
//!   K_X(r₁, r₂) = 15 ⟨X_5^s(k̂, r₁q̂₁, −r₁q̂₁, r₂q̂₂, −r₂q̂₂)⟩_{q̂₁, q̂₂},
//! P15_X(k)/P(k) = (k⁶/4π⁴) ∫∫ dr₁dr₂ r₁²r₂² K_X(r₁, r₂) P(kr₁) P(kr₂), for every linear spectrum.
//! P15_δθ = (P15_δδ + P15_θθ)/2 (the convention of P13_δθ; both legs: 2P15 enters the 2-loop correction).
//!
//! **Angular table.** K_X is a 3-D integral over the cosines x_i = k̂·q̂_i and the relative azimuth φ. The
//! kernel is invariant under q_i → −q_i, so x_i ∈ [0, 1], φ ∈ [0, π] suffice; x_i is traded for
//! p_i = |k̂ − r_i q̂_i| (dx_i = p_i dp_i / r_i), which smooths the cone of |k − q_i| at r_i ≈ 1.
//! Gauss–Legendre of order [`ANGULAR_ORDER`] in (p₁, p₂, φ); the error estimate is the change with order
//! [`ANGULAR_ORDER_COARSE`] (measured convergence: ≲ 1e-6 relative at order 20 except near r₁ = r₂ = 1).
//! The kernel is symmetric in r₁ ↔ r₂, so the radial integral runs over the triangle r₂ ≤ r₁ (twice) in
//! u_i = ln r_i ∈ [ln [`R_MIN`], ln [`R_END`]], on Gauss–Legendre panels whose edges follow the lines
//! where K is not smooth (r_i = 1, r₁ ± r₂ = 1). The table stores K at every node of that rule and of a
//! lower-order rule on the same panels (the radial error estimate). It does not depend on k or on the
//! spectrum: it is built once (about 35 s on 2 cores) and cached on disk by a [`TableStore`](crate::store::TableStore).
//!
//! Limits (tests): K_F → ½K₁(r₁)K₁(r₂) when r₁, r₂ ≪ 1 (K₁ = 3⟨F_3^s(k, q, −q)⟩); K_F → −β/(r₁² + r₂²)·…
//! in the UV with β = 22382/429975 at r₁ = r₂ ≫ 1 and 120424/3009825 for 1 ≪ r₂ ≪ r₁ (Bernardeau, Taruya &
//! Nishimichi 2014).
//!
//! Range: q = kr is cut to [q_min, q_max] of the [`Precision`](crate::precision::Precision) and to
//! r ∈ [R_MIN, R_END]. Beyond r = R_MAX the f64 kernel loses its O(k²/q²) UV value to cancellation
//! (at r = 1e3 already ~1e-6 of its terms), so K is extrapolated there with its UV asymptotics
//! ([`uv_kernel`]). P15 at small k is dominated by q ≫ k (P15/P → −c k², c ∝ ∫∫P P/(q₁² + q₂²)), so
//! the UV range matters: see the README for the sensitivity to q_max.

use super::lattice::Lattice;
use super::Estimate;
use crate::integrate::{panel_edges, GaussLegendre};
use crate::linear::LinearSpectrum;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Smallest r = q/k of the radial rule.
pub const R_MIN: f64 = 1e-5;
/// Largest r = q/k at which the kernel is integrated over angles (f64 loses its O(1/r²) UV value to
/// cancellation beyond: ~1e-6 relative at r = 1e3).
pub const R_MAX: f64 = 1e3;
/// Largest r = q/k of the radial rule; K is extrapolated from r ≤ [`R_MAX`] beyond (see [`uv_kernel`]).
pub const R_END: f64 = 1e6;
/// Below this r₂ the UV extrapolation in r₁ keeps r₂ fixed; above it, it is homogeneous in (r₁, r₂).
const R_UV_JOINT: f64 = 30.0;
/// Gauss–Legendre order of the angular integrals in (p₁, p₂, φ).
pub const ANGULAR_ORDER: usize = 20;
/// Order of the angular error estimate.
pub const ANGULAR_ORDER_COARSE: usize = 14;
/// Gauss–Legendre order per radial panel (the error estimate uses order − 2 on the same panels).
const RADIAL_ORDER: usize = 6;
/// Version of the table layout and rules, part of the cache file name.
const TABLE_VERSION: u32 = 2;

/// The angular kernels [K_F, K_G](r₁, r₂) = 15⟨[F, G]_5^s(k, q₁, −q₁, q₂, −q₂)⟩ with Gauss–Legendre of
/// order `order` in each of (p₁, p₂, φ).
pub fn p15_angular_kernel(r1: f64, r2: f64, order: usize) -> [f64; 2] {
    let rule = GaussLegendre::new(order);
    let range = |r: f64| ((1.0 - r).abs(), (1.0 + r * r).sqrt());
    let ((a1, b1), (a2, b2)) = (range(r1), range(r2));
    let (cos_phi, w_phi): (Vec<f64>, Vec<f64>) =
        rule.on(0.0, PI).map(|(p, w)| (p.cos(), w / PI)).unzip();
    let mut acc = [0.0; 2];
    for (p1, w1) in rule.on(a1, b1) {
        let x1 = ((1.0 + r1 * r1 - p1 * p1) / (2.0 * r1)).clamp(-1.0, 1.0);
        let s1 = (1.0 - x1 * x1).sqrt();
        let j1 = w1 * p1 / r1;
        for (p2, w2) in rule.on(a2, b2) {
            let x2 = ((1.0 + r2 * r2 - p2 * p2) / (2.0 * r2)).clamp(-1.0, 1.0);
            let s2 = (1.0 - x2 * x2).sqrt();
            let j = j1 * w2 * p2 / r2;
            let gram = |c: f64| {
                let q12 = r1 * r2 * (x1 * x2 + s1 * s2 * c);
                [1.0, r1 * x1, r2 * x2, r1 * r1, q12, r2 * r2]
            };
            // Four φ nodes per call of the four-configuration kernel, the rest one by one; summed in node
            // order either way.
            let mut inner = [0.0; 2];
            let mut add = |w: f64, [f, g]: [f64; 2]| {
                inner[0] += w * f;
                inner[1] += w * g;
            };
            let (c4, w4) = (cos_phi.chunks_exact(4), w_phi.chunks_exact(4));
            let (c_rest, w_rest) = (c4.remainder(), w4.remainder());
            for (c, w) in c4.zip(w4) {
                let kernels = pt_kernels::propagator_5_x4(&std::array::from_fn(|l| gram(c[l])));
                for (&w, kernel) in w.iter().zip(kernels) {
                    add(w, kernel);
                }
            }
            for (&c, &w) in c_rest.iter().zip(w_rest) {
                add(w, pt_kernels::propagator_5(&gram(c)));
            }
            acc[0] += j * inner[0];
            acc[1] += j * inner[1];
        }
    }
    acc.map(|a| 15.0 * a)
}

/// [K_F, K_G](r₁, r₂) for r₁ ≥ r₂, with the UV asymptotics beyond [`R_MAX`]: for r₁ ≫ max(1, r₂)
/// K = c(r₂)/r₁², and for r₁, r₂ ≫ 1 K is homogeneous of degree −2, so
/// K(r₁, r₂) = K(R_MAX, r₂)(R_MAX/r₁)² for r₂ < [`R_UV_JOINT`] and K(R_MAX, r₂R_MAX/r₁)(R_MAX/r₁)² above
/// (relative errors O((r₂/r₁)²) and O(1/r₂²), ≲ 1e-3 of a part of the integral that is itself small).
pub fn uv_kernel(r1: f64, r2: f64, order: usize) -> [f64; 2] {
    if r1 <= R_MAX {
        return p15_angular_kernel(r1, r2, order);
    }
    let s = R_MAX / r1;
    let k = if r2 < R_UV_JOINT {
        p15_angular_kernel(R_MAX, r2, order)
    } else {
        p15_angular_kernel(R_MAX, r2 * s, order)
    };
    k.map(|v| v * s * s)
}

/// One node of a radial rule on the triangle u₂ ≤ u₁: u_i = ln r_i and the weight of
/// 2 r₁³ r₂³ du₁ du₂ (the 2 for the other half of the square).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RadialNode {
    pub(crate) u1: f64,
    pub(crate) u2: f64,
    pub(crate) w: f64,
}

/// Largest panel width in u = ln r at u: 0.15 near r ~ 1, growing to 1 in the tails.
fn width(u: f64) -> f64 {
    (0.15 * (1.0 + 0.5 * (u.abs() - 1.5).max(0.0))).min(1.0)
}

/// Panel edges of [a, b] with the given break points inserted, panels at most `width(u)` wide.
pub(crate) fn edges_with(
    a: f64,
    b: f64,
    breaks: &[f64],
    width: impl Fn(f64) -> f64 + Copy,
) -> Vec<f64> {
    let mut cuts = vec![a];
    cuts.extend(
        breaks
            .iter()
            .copied()
            .filter(|&x| x > a + 1e-9 && x < b - 1e-9),
    );
    cuts.push(b);
    cuts.sort_by(f64::total_cmp);
    let mut out = vec![a];
    for w in cuts.windows(2) {
        out.extend(panel_edges(w[0], w[1], width).into_iter().skip(1));
    }
    out
}

/// Panel edges of [a, b] with the given break points inserted.
fn edges(a: f64, b: f64, breaks: &[f64]) -> Vec<f64> {
    edges_with(a, b, breaks, width)
}

/// The radial rule of Gauss–Legendre order `order` on the triangle, grouped by outer node.
fn radial_rule(order: usize) -> Vec<RadialNode> {
    let rule = GaussLegendre::new(order);
    let (lo, hi) = (R_MIN.ln(), R_END.ln());
    // K is not smooth where r₁ = 1, r₁ = ½ (where r₂ = 1 − r₁ meets r₂ = r₁) and r₁ = 2 (r₂ = r₁ − 1 = 1).
    let outer = edges(lo, hi, &[0.0, 0.5f64.ln(), 2f64.ln(), R_MAX.ln()]);
    let mut nodes = Vec::new();
    for e in outer.windows(2) {
        for (u1, w1) in rule.on(e[0], e[1]) {
            let r1 = u1.exp();
            let breaks = [
                0.0,
                (1.0 - r1).abs().max(1e-300).ln(),
                R_UV_JOINT.ln(),
                R_MAX.ln(),
            ];
            for f in edges(lo, u1, &breaks).windows(2) {
                for (u2, w2) in rule.on(f[0], f[1]) {
                    let w = 2.0 * w1 * w2 * (3.0 * (u1 + u2)).exp();
                    nodes.push(RadialNode { u1, u2, w });
                }
            }
        }
    }
    nodes
}

/// M kernel values at every node of the fine radial rule at the fine and the coarse angular order, and
/// at every node of the coarse radial rule at the fine angular order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NodeKernels<const M: usize> {
    pub(crate) fine: Vec<[f64; M]>,
    pub(crate) fine_coarse_angle: Vec<[f64; M]>,
    pub(crate) coarse: Vec<[f64; M]>,
}

/// The table: the fine and the coarse radial rule with [K_F, K_G] at their nodes, and the kernels of
/// the propagator part derived from them (cosmology-independent, so made once with the table).
#[derive(Debug, Clone, PartialEq)]
pub struct P15Table {
    pub(crate) fine: Vec<RadialNode>,
    pub(crate) coarse: Vec<RadialNode>,
    /// [K_F, K_G].
    pub(crate) p15: NodeKernels<2>,
    /// 2K − K₁(r₁)K₁(r₂) for δδ, δθ, θθ (see [`P15Table::propagator_part`]).
    pub(crate) propagator: NodeKernels<3>,
}

impl P15Table {
    /// The memory the angular table holds \[bytes\] (a plan that uses it counts it once).
    pub const MEMORY: f64 = 4e6;
}

impl P15Table {
    /// The table's file name in a [`TableStore`](crate::store::TableStore) directory:
    /// `p15-v<version>-<orders>.bin` (little-endian f64). Delete the file to rebuild the table.
    pub fn file_name() -> String {
        format!("p15-v{TABLE_VERSION}-a{ANGULAR_ORDER}-{ANGULAR_ORDER_COARSE}-r{RADIAL_ORDER}.bin")
    }
}

impl P15Table {
    /// Number of (fine, coarse) radial nodes.
    pub fn len(&self) -> (usize, usize) {
        (self.fine.len(), self.coarse.len())
    }

    /// Whether the table is empty (never, for a built table).
    pub fn is_empty(&self) -> bool {
        self.fine.is_empty()
    }

    /// Builds the table (in parallel over nodes).
    pub fn build(progress: &(dyn Fn(usize, usize) + Sync)) -> Self {
        Self::with_kernel(progress, uv_kernel)
    }

    /// A table of another angular kernel `kernel(r₁, r₂, angular order)` → [K_F, K_G] on the same radial
    /// rules (for tests: e.g. the factorised ½K₁(r₁)K₁(r₂), for which 2P15 = (P13/P)² P).
    pub fn with_kernel(
        progress: &(dyn Fn(usize, usize) + Sync),
        kernel: impl Fn(f64, f64, usize) -> [f64; 2] + Sync,
    ) -> Self {
        let (fine, coarse) = (radial_rule(RADIAL_ORDER), radial_rule(RADIAL_ORDER - 2));
        let total = fine.len() + coarse.len();
        let done = std::sync::atomic::AtomicUsize::new(0);
        let tick = || {
            let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            if n.is_multiple_of(256) || n == total {
                progress(n, total);
            }
        };
        let kernels = |nodes: &[RadialNode], both: bool| -> Vec<[[f64; 2]; 2]> {
            nodes
                .par_iter()
                .map(|n| {
                    let (r1, r2) = (n.u1.exp(), n.u2.exp());
                    let fine = kernel(r1, r2, ANGULAR_ORDER);
                    let coarse = if both {
                        kernel(r1, r2, ANGULAR_ORDER_COARSE)
                    } else {
                        fine
                    };
                    tick();
                    [fine, coarse]
                })
                .collect()
        };
        let f = kernels(&fine, true);
        let c = kernels(&coarse, false);
        let p15 = NodeKernels {
            fine: f.iter().map(|k| k[0]).collect(),
            fine_coarse_angle: f.iter().map(|k| k[1]).collect(),
            coarse: c.iter().map(|k| k[0]).collect(),
        };
        Self::from_parts(fine, coarse, p15)
    }

    /// The table of the rules and the P15 kernels, with the propagator-part kernels
    /// 2K_XY − K₁X(r₁)K₁Y(r₂) (symmetrised), K₁ = 3⟨X_3^s(k, q, −q)⟩ from the closed form
    /// ([`super::k1_kernels`]). 2P15_δθ is the mean of δδ and θθ, P33red_δθ = P13_δ P13_θ/P.
    fn from_parts(fine: Vec<RadialNode>, coarse: Vec<RadialNode>, p15: NodeKernels<2>) -> Self {
        let propagator = |nodes: &[RadialNode], kernels: &[[f64; 2]]| -> Vec<[f64; 3]> {
            nodes
                .par_iter()
                .zip(kernels)
                .map(|(n, &[kf, kg])| {
                    let (a, b) = (super::k1_kernels(n.u1.exp()), super::k1_kernels(n.u2.exp()));
                    [
                        2.0 * kf - a[0] * b[0],
                        kf + kg - 0.5 * (a[0] * b[1] + a[1] * b[0]),
                        2.0 * kg - a[1] * b[1],
                    ]
                })
                .collect()
        };
        let propagator = NodeKernels {
            fine: propagator(&fine, &p15.fine),
            fine_coarse_angle: propagator(&fine, &p15.fine_coarse_angle),
            coarse: propagator(&coarse, &p15.coarse),
        };
        Self {
            fine,
            coarse,
            p15,
            propagator,
        }
    }

    /// The table as the values of its file (see [`TableStore`](crate::store::TableStore)).
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let mut values = vec![self.fine.len() as f64, self.coarse.len() as f64];
        for i in 0..self.fine.len() {
            values.extend(
                self.p15.fine[i]
                    .into_iter()
                    .chain(self.p15.fine_coarse_angle[i]),
            );
        }
        values.extend(self.p15.coarse.iter().flatten());
        values
    }

    /// The table from the values of its file, or `None` if they do not fit the rules or a few
    /// recomputed entries differ (a stale or corrupted file).
    pub(crate) fn from_f64s(values: &[f64]) -> Option<Self> {
        let (fine, coarse) = (radial_rule(RADIAL_ORDER), radial_rule(RADIAL_ORDER - 2));
        if values.len() != 2 + 4 * fine.len() + 2 * coarse.len()
            || values[0] != fine.len() as f64
            || values[1] != coarse.len() as f64
            || values.iter().any(|v| !v.is_finite())
        {
            return None;
        }
        let f = &values[2..2 + 4 * fine.len()];
        let c = &values[2 + 4 * fine.len()..];
        // A stale cache (other kernels or rules under the same name) is caught by recomputing a few
        // entries; any mismatch means a rebuild.
        for i in [0, fine.len() / 3, fine.len() / 2, fine.len() - 1] {
            let n = fine[i];
            let k = uv_kernel(n.u1.exp(), n.u2.exp(), ANGULAR_ORDER);
            let stored = [f[4 * i], f[4 * i + 1]];
            if (0..2).any(|x| (k[x] - stored[x]).abs() > 1e-12 * k[x].abs().max(1e-300)) {
                return None;
            }
        }
        let p15 = NodeKernels {
            fine: f.chunks_exact(4).map(|v| [v[0], v[1]]).collect(),
            fine_coarse_angle: f.chunks_exact(4).map(|v| [v[2], v[3]]).collect(),
            coarse: c.chunks_exact(2).map(|v| [v[0], v[1]]).collect(),
        };
        Some(Self::from_parts(fine, coarse, p15))
    }

    /// [P15_δδ, P15_δθ, P15_θθ] at each k [(Mpc/h)^3] for the linear `spectrum`, integrated over
    /// q ∈ [q_min, q_max] (P̃ interpolated on the lattice of step `lattice_step` in ln q), in parallel
    /// over k. The error is |fine − coarse radial rule| + Σ|w K_fine − w K_coarse angle| P P.
    pub fn evaluate(
        &self,
        k: &[f64],
        spectrum: &LinearSpectrum,
        q_range: (f64, f64),
        lattice_step: f64,
    ) -> Vec<[Estimate; 3]> {
        self.integrate(&self.p15, k, spectrum, q_range, lattice_step)
            .into_iter()
            .map(|[dd, tt]| [dd, Estimate::mean(dd, tt), tt])
            .collect()
    }

    /// The infrared-safe propagator part 2P15_XY − P13_X P13_Y/P of the 2-loop correction for
    /// [δδ, δθ, θθ] at each k [(Mpc/h)^3], as one integral of the kernel 2K_XY − K₁X(r₁)K₁Y(r₂)
    /// (symmetrised), K₁ = 3⟨X_3^s(k, q, −q)⟩ from the closed form ([`super::k1_kernels`]): its
    /// 1/r² infrared pieces cancel at each node, so no large terms are subtracted afterwards. Integrated
    /// and with errors as [`Self::evaluate`].
    pub fn propagator_part(
        &self,
        k: &[f64],
        spectrum: &LinearSpectrum,
        q_range: (f64, f64),
        lattice_step: f64,
    ) -> Vec<[Estimate; 3]> {
        self.integrate(&self.propagator, k, spectrum, q_range, lattice_step)
    }

    /// Σ over the radial rule of w P(k r₁) P(k r₂) × `kernels` at each k, normalised to (Mpc/h)^3, with
    /// the error |fine − coarse radial rule| + Σ|w ΔK_angle| P P (ΔK_angle: the kernels at the fine
    /// minus the coarse angular order).
    fn integrate<const M: usize>(
        &self,
        kernels: &NodeKernels<M>,
        k: &[f64],
        spectrum: &LinearSpectrum,
        q_range: (f64, f64),
        lattice_step: f64,
    ) -> Vec<[Estimate; M]> {
        let lattice = Lattice::new(q_range.0, q_range.1, lattice_step);
        let samples = lattice.sample(spectrum);
        let p_at = |x: f64| lattice.at_ln_or_zero(&samples, x);
        k.par_iter()
            .map(|&k| {
                let ln_k = k.ln();
                // Nodes come in runs of equal u₁; a run where P(k r₁) = 0 (outside the q range) is
                // skipped.
                let sum = |nodes: &[RadialNode], kernels: &[[f64; M]], alt: Option<&[[f64; M]]>| {
                    let (mut total, mut angular) = ([0.0; M], [0.0; M]);
                    let (mut u1, mut p1) = (f64::NAN, 0.0);
                    for (i, n) in nodes.iter().enumerate() {
                        if n.u1 != u1 {
                            (u1, p1) = (n.u1, p_at(ln_k + n.u1));
                        }
                        if p1 == 0.0 {
                            continue;
                        }
                        let pp = n.w * p1 * p_at(ln_k + n.u2);
                        let kernel = &kernels[i];
                        for x in 0..M {
                            total[x] += pp * kernel[x];
                        }
                        if let Some(alt) = alt {
                            let alt = &alt[i];
                            for x in 0..M {
                                angular[x] += (pp * (kernel[x] - alt[x])).abs();
                            }
                        }
                    }
                    (total, angular)
                };
                let (fine, angular) =
                    sum(&self.fine, &kernels.fine, Some(&kernels.fine_coarse_angle));
                let (coarse, _) = sum(&self.coarse, &kernels.coarse, None);
                let norm = k.powi(6) / (4.0 * PI.powi(4)) * spectrum.eval(k);
                std::array::from_fn(|x| {
                    Estimate::new(
                        norm * fine[x],
                        norm.abs() * ((fine[x] - coarse[x]).abs() + angular[x]),
                    )
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radial_rule_integrates_a_separable_power_law() {
        // The weights include 2r₁³r₂³, so Σ w h(u₁)h(u₂) = (∫ r³h du)² for a separable symmetric
        // integrand; with r³h = r²/(1+r²)², ∫ r³h du = ∫ r dr/(1+r²)² = 1/2.
        let nodes = radial_rule(RADIAL_ORDER);
        let h = |u: f64| {
            let r = u.exp();
            r * r / (1.0 + r * r).powi(2) / r.powi(3)
        };
        let total: f64 = nodes.iter().map(|n| n.w * h(n.u1) * h(n.u2)).sum();
        // Over [R_MIN, R_END] only: ∫ r dr/(1+r²)² = [−1/(2(1+r²))].
        let one = 0.5 / (1.0 + R_MIN * R_MIN) - 0.5 / (1.0 + R_END * R_END);
        assert!((total - one * one).abs() < 1e-12, "{total}");
    }
}
