//! The mode-coupling terms P22 as a fixed 2-D node set per k.
//!
//! P22_XY(k) = 2 ∫d³q/(2π)³ X_2^s(q, k−q) Y_2^s(q, k−q) P(q) P(|k−q|), X, Y ∈ {F, G}. In the variables
//! q and p = |k − q| (d³q = 2π q p dq dp / k) the integrand is symmetric under q ↔ p, so the half p ≥ q
//! suffices:
//!   P22_XY(k) = (1/π² k) ∫ dln q  q² P(q) ∫_{max(q, |k−q|)}^{min(k+q, q_max)} dp  p X₂Y₂ P(p),
//! with, for c = q·(k−q) = (k² − q² − p²)/2,
//!   F_2^s = 5/7 + (c/2)(1/q² + 1/p²) + (2/7) c²/(q²p²),  G_2^s = 3/7 + (c/2)(1/q² + 1/p²) + (4/7) c²/(q²p²).
//! Restricting to p ≥ q removes the integrable singularity at p → 0 (F_2^s ~ 1/p there); what is left is
//! smooth except for kinks of the outer integrand at q = k/2 (where the lower limit switches from k − q to
//! q) and at q = q_max − k, which are panel edges.
//!
//! Quadrature: Gauss–Legendre panels in ln q (outer) and in p (inner). Panels are at most
//! `ln_width` wide in ln q, and inside the feature band q, p < `band_end` also at most `linear_width` wide
//! in q or p, so that baryon acoustic oscillations (period Δk ≈ 2π/r_s ≈ 0.06 h/Mpc) are resolved.
//! Every node stores its lattice position (P̃ is interpolated there) and the weights of F₂², F₂G₂ and G₂²
//! including every factor, so that a new spectrum costs one interpolation and three multiply–adds per node.

use super::lattice::Lattice;
use crate::integrate::{lagrange4, panel_edges, GaussLegendre};
use rayon::prelude::*;
use std::f64::consts::PI;

/// The closed forms [F_2^s, G_2^s](q, k − q) from k², q² and p² = |k − q|².
#[inline]
pub fn f2_g2(k2: f64, q2: f64, p2: f64) -> [f64; 2] {
    let c = 0.5 * (k2 - q2 - p2);
    let a = 0.5 * c * (1.0 / q2 + 1.0 / p2);
    let b = c * c / (q2 * p2);
    [5.0 / 7.0 + a + 2.0 / 7.0 * b, 3.0 / 7.0 + a + 4.0 / 7.0 * b]
}

/// How P22 panels are laid out (from [`crate::precision::Precision`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    /// Gauss–Legendre order per panel (outer, and inner unless narrow).
    pub order: usize,
    /// Order of inner ranges narrower than `narrow_width` in ln p.
    pub narrow_order: usize,
    /// See `narrow_order`.
    pub narrow_width: f64,
    /// Largest panel width in ln q near q ~ k (outer) and in ln p (inner).
    pub ln_width: f64,
    /// Growth of the outer ln width with |ln(q/k)|.
    pub tail_growth: f64,
    /// Largest panel width in q or p [h/Mpc] below `band_end`.
    pub linear_width: f64,
    /// End of the feature band [h/Mpc].
    pub band_end: f64,
}

impl Layout {
    /// The layout of `precision`, with every Gauss–Legendre order lowered by `drop` (the half-resolution
    /// rule of the error estimates: `drop` for the full order, `drop / 2` for the narrow-range order,
    /// whose integrand is a polynomial of degree ~5 that a 3-point rule still integrates well).
    pub fn new(precision: &crate::precision::Precision, drop: usize) -> Self {
        Self {
            order: precision.p22_order.saturating_sub(drop).max(1),
            narrow_order: precision.p22_narrow_order.saturating_sub(drop / 2).max(1),
            narrow_width: precision.p22_narrow_width,
            ln_width: precision.p22_ln_width,
            tail_growth: precision.p22_tail_growth,
            linear_width: precision.p22_linear_width,
            band_end: precision.p22_band_end,
        }
    }

    /// Largest inner panel width in p at `p` [h/Mpc].
    fn width(&self, p: f64) -> f64 {
        let log = self.ln_width * p;
        if p < self.band_end {
            log.min(self.linear_width)
        } else {
            log
        }
    }

    /// Largest outer panel width in ln q at x = ln q for wavenumber k: `ln_width` near q ~ k, growing
    /// as ln_width · tail_growth · |ln(q/k)| in the tails, where the kernel is a smooth power law, but
    /// never wider than `linear_width` in q inside the feature band.
    fn outer_width(&self, x: f64, k: f64) -> f64 {
        let q = x.exp();
        let ln = self.ln_width * (self.tail_growth * (x - k.ln()).abs()).max(1.0);
        if q < self.band_end {
            ln.min(self.linear_width / q)
        } else {
            ln
        }
    }
}

/// Nodes of all k of a plan, flattened, each with `M` weights.
///
/// Inner nodes store their interpolation stencil (first lattice point and the four Lagrange weights) and
/// the `M` kernel weights in `f32`: their rounding (relative 6e-8, unbiased) is far below the
/// quadrature errors, and halving the memory traffic speeds up the sums ([`P22Nodes::evaluate`]).
#[derive(Debug, Clone)]
pub(crate) struct PairNodes<const M: usize> {
    /// Per k: the range of outer nodes.
    pub k_start: Vec<u32>,
    /// Per outer node: lattice position of q.
    pub outer_u: Vec<f64>,
    /// Per outer node: end (exclusive) of its inner nodes.
    pub outer_end: Vec<u32>,
    /// Per inner node: first lattice point of the interpolation stencil of p.
    pub inner_b: Vec<u32>,
    /// Per inner node: the Lagrange weights of the four stencil points.
    pub inner_l: Vec<[f32; 4]>,
    /// Per inner node: the kernel weights.
    pub inner_w: Vec<[f32; M]>,
}

/// The P22 nodes: weights of F₂², F₂G₂, G₂².
pub(crate) type P22Nodes = PairNodes<3>;

impl<const M: usize> Default for PairNodes<M> {
    fn default() -> Self {
        Self {
            k_start: Vec::new(),
            outer_u: Vec::new(),
            outer_end: Vec::new(),
            inner_b: Vec::new(),
            inner_l: Vec::new(),
            inner_w: Vec::new(),
        }
    }
}

/// The rules of one plan.
struct Rules<'a, K> {
    lattice: &'a Lattice,
    layout: &'a Layout,
    full: GaussLegendre,
    narrow: GaussLegendre,
    kernel: &'a K,
}

impl P22Nodes {
    /// The P22 nodes for every k of `ks` (see the module documentation).
    pub fn p22(ks: &[f64], lattice: &Lattice, layout: &Layout) -> Self {
        // The half p ≥ q of d³q/(2π)³ = q²p dln q dp/(4π²k) counts twice, and P22 = 2∫…
        Self::new(ks, lattice, layout, &|k, q, p, measure| {
            let [f, g] = f2_g2(k * k, q * q, p * p);
            let c = measure / (PI * PI);
            [c * f * f, c * f * g, c * g * g]
        })
    }
}

impl<const M: usize> PairNodes<M> {
    /// The nodes for every k of `ks` on the half p ≥ q of the (q, p = |k − q|) plane (built in parallel
    /// over k; the result does not depend on threads). `kernel(k, q, p, measure)` gives the M weights of
    /// a node, where `measure` = w q² p / k is the quadrature weight of d³q/(2π)³ times 4π², so that
    /// ∫_{p ≥ q} d³q/(2π)³ g = Σ measure · ⟨g⟩_φ/(4π²), ⟨g⟩_φ the average over the azimuth of q about k.
    pub fn new<K>(ks: &[f64], lattice: &Lattice, layout: &Layout, kernel: &K) -> Self
    where
        K: Fn(f64, f64, f64, f64) -> [f64; M] + Sync,
    {
        let rules = Rules {
            lattice,
            layout,
            full: GaussLegendre::new(layout.order),
            narrow: GaussLegendre::new(layout.narrow_order.min(layout.order)),
            kernel,
        };
        let parts: Vec<Self> = ks.par_iter().map(|&k| Self::for_k(k, &rules)).collect();
        let (outer_total, inner_total) = parts.iter().fold((0, 0), |(o, i), part| {
            (o + part.outer_u.len(), i + part.inner_b.len())
        });
        let mut nodes = Self::default();
        nodes.k_start.reserve(parts.len() + 1);
        nodes.outer_u.reserve(outer_total);
        nodes.outer_end.reserve(outer_total);
        nodes.inner_b.reserve(inner_total);
        nodes.inner_l.reserve(inner_total);
        nodes.inner_w.reserve(inner_total);
        for part in parts {
            let (outer, inner) = (nodes.outer_u.len() as u32, nodes.inner_b.len() as u32);
            nodes.k_start.push(outer);
            nodes.outer_u.extend(part.outer_u);
            nodes
                .outer_end
                .extend(part.outer_end.iter().map(|e| e + inner));
            nodes.inner_b.extend(part.inner_b);
            nodes.inner_l.extend(part.inner_l);
            nodes.inner_w.extend(part.inner_w);
        }
        nodes.k_start.push(nodes.outer_u.len() as u32);
        nodes
    }

    /// The nodes of one k (without `k_start`).
    fn for_k<K>(k: f64, rules: &Rules<K>) -> Self
    where
        K: Fn(f64, f64, f64, f64) -> [f64; M],
    {
        let (lattice, layout) = (rules.lattice, rules.layout);
        let (x_min, x_max) = (lattice.x0, lattice.x_end());
        let q_max = x_max.exp();
        let mut nodes = Self::default();
        let mut edges = panel_edges(x_min, x_max, |x| layout.outer_width(x, k));
        // Kinks of the outer integrand; the one at q_max − k only matters when k is not ≪ q_max.
        let kinks = [0.5 * k, if k > 1e-3 * q_max { q_max - k } else { 0.0 }];
        edges.extend(
            kinks
                .iter()
                .map(|q| q.ln())
                .filter(|&x| x > x_min && x < x_max),
        );
        edges.sort_by(f64::total_cmp);
        edges.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        for e in edges.windows(2) {
            for (x, w) in rules.full.on(e[0], e[1]) {
                nodes.push_outer(k, x, w, rules);
            }
        }
        nodes
    }

    /// The inner nodes of outer node (ln q = x, weight w) at wavenumber k.
    fn push_outer<K>(&mut self, k: f64, x: f64, w: f64, rules: &Rules<K>)
    where
        K: Fn(f64, f64, f64, f64) -> [f64; M],
    {
        let (lattice, layout) = (rules.lattice, rules.layout);
        let q = x.exp();
        let (lo, hi) = (q.max((k - q).abs()), (k + q).min(lattice.x_end().exp()));
        if hi <= lo {
            return;
        }
        let factor = w * q * q / k;
        let narrow = hi - lo < 0.5 * layout.width(lo) && (hi / lo).ln() < layout.narrow_width;
        let rule = if narrow { &rules.narrow } else { &rules.full };
        for e in panel_edges(lo, hi, |p| layout.width(p)).windows(2) {
            for (p, v) in rule.on(e[0], e[1]) {
                let weights = (rules.kernel)(k, q, p, factor * v * p);
                let (b, t) = lattice.stencil(lattice.position(p));
                self.inner_b.push(b as u32);
                self.inner_l.push(lagrange4(t).map(|l| l as f32));
                self.inner_w.push(weights.map(|v| v as f32));
            }
        }
        self.outer_u.push(lattice.position(q));
        self.outer_end.push(self.inner_b.len() as u32);
    }

    /// Total number of inner nodes.
    pub fn len(&self) -> usize {
        self.inner_b.len()
    }

    /// The range of inner nodes of k index `i`, and the range of its outer nodes.
    pub fn ranges(&self, i: usize) -> (usize, std::ops::Range<usize>) {
        let (o0, o1) = (self.k_start[i] as usize, self.k_start[i + 1] as usize);
        let start = if o0 == 0 {
            0
        } else {
            self.outer_end[o0 - 1] as usize
        };
        (start, o0..o1)
    }
}

impl P22Nodes {
    /// [P22_δδ, P22_δθ, P22_θθ] at k index `i` from the lattice `samples`.
    pub fn evaluate(&self, i: usize, lattice: &Lattice, samples: &[f64]) -> [f64; 3] {
        let (mut start, outer) = self.ranges(i);
        let mut total = [0.0; 3];
        for o in outer {
            let end = self.outer_end[o] as usize;
            let mut acc = [0.0; 3];
            let nodes = self.inner_b[start..end]
                .iter()
                .zip(&self.inner_l[start..end])
                .zip(&self.inner_w[start..end]);
            for ((&b, l), w) in nodes {
                let s = &samples[b as usize..b as usize + 4];
                let l = l.map(f64::from);
                let pp = (l[0] * s[0] + l[1] * s[1]) + (l[2] * s[2] + l[3] * s[3]);
                acc[0] += f64::from(w[0]) * pp;
                acc[1] += f64::from(w[1]) * pp;
                acc[2] += f64::from(w[2]) * pp;
            }
            let pq = lattice.interpolate(samples, self.outer_u[o]);
            for (t, a) in total.iter_mut().zip(acc) {
                *t += pq * a;
            }
            start = end;
        }
        total
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pt_kernels::mode_coupling_2;

    #[test]
    fn closed_forms_match_generated_kernels() {
        for (k, q, p) in [
            (1.0, 0.3, 0.9),
            (0.1, 2.0, 2.05),
            (1.0, 1e-3, 1.0005),
            (0.5, 0.25, 0.25),
        ] {
            let (k2, q2, p2) = (k * k, q * q, p * p);
            let kq = 0.5 * (k2 + q2 - p2);
            let [f, g] = mode_coupling_2(&[k2, kq, q2]);
            let [cf, cg] = f2_g2(k2, q2, p2);
            assert!(
                (cf - f).abs() < 1e-12 * f.abs().max(1.0),
                "F2 at {k} {q} {p}"
            );
            assert!(
                (cg - g).abs() < 1e-12 * g.abs().max(1.0),
                "G2 at {k} {q} {p}"
            );
        }
    }

    #[test]
    fn panels_split_at_the_kinks() {
        let lattice = Lattice::new(1e-5, 1e3, 0.01);
        let layout = Layout {
            order: 4,
            narrow_order: 3,
            narrow_width: 0.05,
            ln_width: 0.3,
            tail_growth: 0.3,
            linear_width: 0.05,
            band_end: 1.0,
        };
        let nodes = P22Nodes::p22(&[0.1, 0.2], &lattice, &layout);
        assert_eq!(nodes.k_start.len(), 3);
        assert_eq!(*nodes.outer_end.last().unwrap() as usize, nodes.len());
        // Every inner stencil lies inside the lattice.
        assert!(nodes
            .inner_b
            .iter()
            .all(|&b| (b as usize) + 4 <= lattice.len));
    }
}
