//! The 1-loop vertex Γ2^(1-loop) and the two RegPT terms built from it, P24 and PΓ2, as fixed weights.
//!
//! RegPT (Taruya, Bernardeau, Nishimichi & Codis 2012, arXiv:1208.1191) writes its 2-loop spectrum with
//! the 1-loop correction of the two-point propagator (the vertex) Γ2,
//!   Γ2_X(k₁, k₂) = 6 ∫d³p/(2π)³ X_4^s(k₁, k₂, p, −p) P(p),  X = F (δ), G (θ),
//! and two mode-coupling terms (pyregpt's normalisation, that of the shared reference file):
//!   P24_XY = 2 ∫d³q/(2π)³ [X_2 Γ2_Y + Γ2_X Y_2](q, k − q) P(q) P(|k − q|)  (= 2P24 of the paper),
//!   PΓ2_XY = 2 ∫d³q/(2π)³ Γ2_X Γ2_Y(q, k − q) P(q) P(|k − q|)               (3-loop order).
//!
//! Both are the P22 integral with Γ2 in place of a kernel, so the outer integral uses P22's variables
//! q and p = |k − q| (d³q = 2π q p dq dp / k) on the half p ≥ q (×2, the q ↔ k − q symmetry):
//! Gauss–Legendre panels in ln q, edges at k/2, and in p over [max(q, |k − q|), min(k + q, q_max)].
//!
//! The inner integral, with k̂ = ẑ, k₁ = q (s₁, 0, x₁) and p = r (s₂ cos φ, s₂ sin φ, x₂): X_4^s is
//! even in p (its last two arguments swap) and in φ (reflection y → −y), so
//!   Γ2_X = (24/(2π)³) ∫ dln r r³ P(r) ∫_0^1 dx₂ ∫_0^π dφ X_4^s(q, k − q, p, −p),
//! with Gauss–Legendre nodes in x₂ and φ, and in ln r on one fixed set of panels over [q_min, q_max]
//! (narrower inside the BAO band). The angular integral does not depend on the cosmology: the plan
//! stores it, times the radial weights, for every (outer node, r node), and a spectrum then costs
//! Γ2 = Σ_j w_j P(r_j) per outer node (two dot products) and the outer sums.
//!
//! The integrand has kinks where r equals |k₁|, |k₂| or k (the angular integral of X_4^s is
//! continuous with a weak logarithmic singularity of a derivative there, as that of F_3^s in P13);
//! panels that do not have them as edges still converge fast (a prototype with those edges as panel
//! edges, 12 × 12 angular nodes and 6-point panels agreed with fixed panels to ≤ 2e-5 at k = 0.1–0.29).
//! Radial nodes within a factor 4 of q, |k − q| or k get 6 × 6 angular nodes, those below 4 × 4 (the
//! integrand is then nearly a low polynomial in x₂, cos φ); above, the leading terms of X_4^s cancel
//! (UV), so they keep 6 × 6.
//!
//! Panels widen by half their width per unit of ln q outside q ∈ [k/4, 4k] (outer) and ln r outside
//! r ∈ [3e-3, 1] h/Mpc (radial), where the integrands are smooth power laws.
//!
//! Error estimate: |I − I′|, I′ from a coarser layout (3-point panels outer and radial, 4 × 4 and 3 × 3
//! angular nodes), at least 5e-5 |I|. Against a layout with 1.5–2 times the points in every direction
//! the values differ by ≤ 3.4e-5 (k = 0.02, 0.1, 0.25 h/Mpc), against pyregpt by ≤ 6e-4 (k ≤ 0.3).

mod basis;

pub use basis::Gamma2Basis;

use super::lattice::Lattice;
use super::{ByPair, Estimate, Pair};
use crate::integrate::{panel_edges, GaussLegendre};
use crate::linear::LinearSpectrum;
use crate::simd::dot32;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The layout of one evaluation: Gauss–Legendre orders and panel widths.
#[derive(Debug, Clone, Copy)]
struct Layout {
    /// Points per outer panel (in ln q and in p).
    outer: usize,
    /// Points per radial panel of the inner integral.
    radial: usize,
    /// Points in x₂ and in φ where r is within a factor [`NEAR`] of q, |k − q| or k.
    angular: usize,
    /// Points in x₂ and in φ elsewhere, where the angular integrand is nearly a low polynomial.
    angular_far: usize,
    /// Panel width in ln q, ln r and relative width in p (in the core ranges, see [`ln_width`]).
    width: f64,
}

/// Radial nodes within this factor of one of the scales q, |k − q|, k get `Layout::angular` points.
const NEAR: f64 = 4.0;

/// The layout of the values.
const FINE: Layout = Layout {
    outer: 4,
    radial: 4,
    angular: 6,
    angular_far: 4,
    width: 0.4,
};

/// The layout of the error estimate.
const COARSE: Layout = Layout {
    outer: 3,
    radial: 3,
    angular: 4,
    angular_far: 3,
    width: 0.4,
};

/// Largest panel width in q, p or r [h/Mpc] below [`BAND_END`] (BAO period Δk ≈ 0.06 h/Mpc).
const LINEAR_WIDTH: f64 = 0.05;
/// End of the band where panels are at most [`LINEAR_WIDTH`] wide [h/Mpc].
const BAND_END: f64 = 0.4;

/// Radial panels widen outside this range of r [h/Mpc], where r³P(r) times the angular integral is a
/// smooth power law.
const RADIAL_CORE: (f64, f64) = (3e-3, 1.0);
/// Outer panels widen outside q ∈ [k/`OUTER_CORE`, k·`OUTER_CORE`].
const OUTER_CORE: f64 = 4.0;
/// Growth of the panel width per unit of ln x outside the core ranges.
const TAIL_GROWTH: f64 = 0.5;

/// Panel width in ln x at x = e^`ln_x`: `width` in the core range (`core`, in ln x), growing by
/// [`TAIL_GROWTH`] per unit of ln x outside it, never wider than [`LINEAR_WIDTH`] in x below
/// [`BAND_END`].
fn ln_width(ln_x: f64, width: f64, core: (f64, f64)) -> f64 {
    let outside = (core.0 - ln_x).max(ln_x - core.1).max(0.0);
    let w = width * (1.0 + TAIL_GROWTH * outside);
    let x = ln_x.exp();
    if x < BAND_END {
        w.min(LINEAR_WIDTH / x)
    } else {
        w
    }
}

/// The radial nodes (ln r, weight in ln r) of `layout` over [`lo`, `hi`] (ln r).
fn radial_nodes(lo: f64, hi: f64, layout: Layout) -> Vec<(f64, f64)> {
    let rule = GaussLegendre::new(layout.radial);
    let core = (RADIAL_CORE.0.ln(), RADIAL_CORE.1.ln());
    panel_edges(lo, hi, |x| ln_width(x, layout.width, core))
        .windows(2)
        .flat_map(|e| rule.on(e[0], e[1]).collect::<Vec<_>>())
        .collect()
}

/// One outer node: where P(q) and P(p) are read, its weight (every factor but P(q)P(p)), and
/// [F_2^s, G_2^s](q, k − q).
#[derive(Debug, Clone, Copy)]
struct Outer {
    u_q: f64,
    u_p: f64,
    weight: f64,
    f2: [f64; 2],
}

/// The nodes of one layout for every k.
#[derive(Debug, Clone)]
struct Nodes {
    /// The radial nodes of Γ2: (ln r_j, weight in ln r).
    radial: Vec<(f64, f64)>,
    /// Per k: the range of its outer nodes.
    k_start: Vec<usize>,
    outer: Vec<Outer>,
    /// Per outer node: the weights of P(r_j) in Γ2_F over the radial nodes, then those in Γ2_G.
    weights: Vec<f32>,
}

/// The angular nodes (x₂, s₂ cos φ, weight) of the `n` × `n` Gauss–Legendre rule on [0, 1] × [0, π].
fn directions(n: usize) -> Vec<(f64, f64, f64)> {
    let rule = GaussLegendre::new(n);
    let mut out = Vec::with_capacity(n * n);
    for (x2, wx) in rule.on(0.0, 1.0) {
        let s2 = (1.0 - x2 * x2).max(0.0).sqrt();
        for (phi, wp) in rule.on(0.0, PI) {
            out.push((x2, s2 * phi.cos(), wx * wp));
        }
    }
    out
}

/// Γ2's inner weights at one outer node (k, q, p = |k − q|) over the radial nodes `(ln r, w)`, with the
/// angular nodes `near` for r ≥ min(q, p, k)/[`NEAR`] and `far` below ([`directions`]).
fn inner_weights(
    k: f64,
    q: f64,
    p: f64,
    radial: &[(f64, f64)],
    [near, far]: [&[(f64, f64, f64)]; 2],
) -> Vec<[f32; 2]> {
    let x1 = ((k * k + q * q - p * p) / (2.0 * k * q)).clamp(-1.0, 1.0);
    let s1 = (1.0 - x1 * x1).max(0.0).sqrt();
    let lo = q.min(p).min(k) / NEAR;
    let norm = 24.0 / (2.0 * PI).powi(3);
    radial
        .iter()
        .map(|&(ln_r, w)| {
            let r = ln_r.exp();
            let directions = if r >= lo { near } else { far };
            let mut sum = [0.0; 2];
            for chunk in directions.chunks(4) {
                let grams: [[f64; 6]; 4] = std::array::from_fn(|i| {
                    let (x2, s2c, _) = chunk[i.min(chunk.len() - 1)];
                    [
                        k * k,
                        k * q * x1,
                        k * r * x2,
                        q * q,
                        q * r * (x1 * x2 + s1 * s2c),
                        r * r,
                    ]
                });
                let m = pt_kernels::mode_coupling_4_x4(&grams);
                for (i, &(_, _, wa)) in chunk.iter().enumerate() {
                    sum[0] += wa * m[i][0];
                    sum[1] += wa * m[i][1];
                }
            }
            let f = norm * w * r.powi(3);
            [(f * sum[0]) as f32, (f * sum[1]) as f32]
        })
        .collect()
}

impl Nodes {
    /// The nodes of `layout` on `k`, without the inner weights.
    fn layout(k: &[f64], lattice: &Lattice, layout: Layout) -> Self {
        let (lo, hi) = (lattice.x0, lattice.x_end());
        let radial = radial_nodes(lo, hi, layout);
        let outer_rule = GaussLegendre::new(layout.outer);
        let q_max = hi.exp();
        let mut k_start = vec![0];
        let mut outer = Vec::new();
        for &k in k {
            let half = (0.5 * k).ln().clamp(lo, hi);
            let core = ((k / OUTER_CORE).ln(), (k * OUTER_CORE).ln());
            let width = |x| ln_width(x, layout.width, core);
            let mut edges = panel_edges(lo, half, width);
            if half < hi {
                edges.extend(&panel_edges(half, hi, width)[1..]);
            }
            for e in edges.windows(2) {
                for (ln_q, wq) in outer_rule.on(e[0], e[1]) {
                    let q = ln_q.exp();
                    let (pa, pb) = (q.max((k - q).abs()), (k + q).min(q_max));
                    if pa >= pb {
                        continue;
                    }
                    let p_edges = panel_edges(pa, pb, |p| width(p.ln()) * p);
                    for pe in p_edges.windows(2) {
                        for (p, wp) in outer_rule.on(pe[0], pe[1]) {
                            // ∫d³q/(2π)³ on p ≥ q (×2), times RegPT's 2.
                            let weight =
                                4.0 * wq * q * q * wp * p * 2.0 * PI / (k * (2.0 * PI).powi(3));
                            outer.push(Outer {
                                u_q: lattice.position(q),
                                u_p: lattice.position(p),
                                weight,
                                f2: super::f2_g2(k * k, q * q, p * p),
                            });
                        }
                    }
                }
            }
            k_start.push(outer.len());
        }
        Self {
            radial,
            k_start,
            outer,
            weights: Vec::new(),
        }
    }

    /// The nodes with the inner weights of every outer node (the cosmology-independent work), in
    /// parallel; `report(n)` after every n outer nodes.
    fn with_weights(
        mut self,
        k: &[f64],
        lattice: &Lattice,
        layout: Layout,
        report: &(dyn Fn(usize) + Sync),
    ) -> Self {
        let (near, far) = (directions(layout.angular), directions(layout.angular_far));
        let mut ks = Vec::with_capacity(self.outer.len());
        for (i, &k) in k.iter().enumerate() {
            ks.extend(std::iter::repeat_n(
                k,
                self.k_start[i + 1] - self.k_start[i],
            ));
        }
        const CHUNK: usize = 64;
        self.weights = self
            .outer
            .par_chunks(CHUNK)
            .zip(ks.par_chunks(CHUNK))
            .flat_map_iter(|(outer, ks)| {
                let w: Vec<f32> = outer
                    .iter()
                    .zip(ks)
                    .flat_map(|(o, &k)| {
                        let (q, p) = (
                            (lattice.x0 + o.u_q * lattice.step).exp(),
                            (lattice.x0 + o.u_p * lattice.step).exp(),
                        );
                        let w = inner_weights(k, q, p, &self.radial, [&near, &far]);
                        let (f, g): (Vec<f32>, Vec<f32>) = w.iter().map(|w| (w[0], w[1])).unzip();
                        f.into_iter().chain(g)
                    })
                    .collect();
                report(outer.len());
                w
            })
            .collect();
        self
    }

    /// P̃ at the radial nodes, from the lattice `samples`.
    fn radial_spectrum(&self, lattice: &Lattice, samples: &[f64]) -> Vec<f64> {
        self.radial
            .iter()
            .map(|&(ln_r, _)| lattice.interpolate(samples, (ln_r - lattice.x0) / lattice.step))
            .collect()
    }

    /// [P24, PΓ2] of the three pairs at k index `i`, from the lattice `samples` and P at the radial nodes.
    fn evaluate(&self, i: usize, lattice: &Lattice, samples: &[f64], p_r: &[f64]) -> [[f64; 3]; 2] {
        let n = self.radial.len();
        let mut out = [[0.0; 3]; 2];
        for j in self.k_start[i]..self.k_start[i + 1] {
            let o = &self.outer[j];
            let w = &self.weights[2 * j * n..2 * (j + 1) * n];
            let g = [dot32(&w[..n], p_r), dot32(&w[n..], p_r)];
            let spectra = o.weight
                * lattice.interpolate(samples, o.u_q)
                * lattice.interpolate(samples, o.u_p);
            for (m, (x, y)) in PAIRS.into_iter().enumerate() {
                out[0][m] += spectra * (o.f2[x] * g[y] + g[x] * o.f2[y]);
                out[1][m] += spectra * g[x] * g[y];
            }
        }
        out
    }
}

/// Relative floor of the error estimate: the default layout differs from one with 1.5–2 times the
/// points in every direction by ≤ 3.4e-5 (k = 0.02, 0.1, 0.25; test below), where |fine − coarse| is
/// mostly 10–100 times that but can vanish by accident.
const ERROR_FLOOR: f64 = 5e-5;

/// (X, Y) of δδ, δθ, θθ: 0 = F, 1 = G.
const PAIRS: [(usize, usize); 3] = [(0, 0), (0, 1), (1, 1)];

/// RegPT's Γ2 terms of δδ, δθ, θθ at each k [(Mpc/h)^3] (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Gamma2Terms {
    /// P24_XY = 2∫[X_2 Γ2_Y + Γ2_X Y_2] P P: the whole P24 contribution to the 2-loop correction
    /// (2P24 in the paper's notation, P24 in RegPT's).
    pub p24: ByPair<Vec<Estimate>>,
    /// PΓ2_XY = 2∫Γ2_X Γ2_Y P P (3-loop order; in the 2-loop RegPT spectrum).
    pub p_gamma2: ByPair<Vec<Estimate>>,
    /// The projection residual if Γ2 came from linear forms on a basis ([`Gamma2Basis`]).
    pub basis_residual: Option<f64>,
}

/// The Γ2 weights of a k grid (cosmology independent); [`evaluate`](Self::evaluate) per spectrum.
#[derive(Debug, Clone)]
pub struct Gamma2Plan {
    lattice: Lattice,
    fine: Nodes,
    coarse: Nodes,
}

/// Bytes per output k of RegPT's Γ2 weights (measured 1.1 MB, rounded up).
const BYTES_PER_K: f64 = 1.2e6;

impl Gamma2Plan {
    /// The estimated memory of the weights on `nk` wavenumbers \[bytes\].
    pub fn memory_estimate(nk: usize) -> f64 {
        BYTES_PER_K * nk as f64
    }

    /// The plan for wavenumbers `k` [h/Mpc], integrals over q ∈ `q_range` with P sampled on a lattice of
    /// step `lattice_step` in ln q. Takes ~0.1 s per k on one core.
    pub fn new(k: &[f64], q_range: (f64, f64), lattice_step: f64) -> Self {
        Self::with_progress(k, q_range, lattice_step, &|_, _| {})
    }

    /// [`new`](Self::new), calling `progress(done, total)` with the outer nodes done (both layouts).
    pub fn with_progress(
        k: &[f64],
        q_range: (f64, f64),
        lattice_step: f64,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Self {
        let lattice = Lattice::new(q_range.0, q_range.1, lattice_step);
        let (fine, coarse) = (
            Nodes::layout(k, &lattice, FINE),
            Nodes::layout(k, &lattice, COARSE),
        );
        let total = fine.outer.len() + coarse.outer.len();
        let done = AtomicUsize::new(0);
        let report = |n: usize| progress(done.fetch_add(n, Ordering::Relaxed) + n, total);
        Self {
            fine: fine.with_weights(k, &lattice, FINE, &report),
            coarse: coarse.with_weights(k, &lattice, COARSE, &report),
            lattice,
        }
    }

    /// Number of k.
    pub fn len(&self) -> usize {
        self.fine.k_start.len() - 1
    }

    /// Whether the plan has no k.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// P24 and PΓ2 of `spectrum` at the plan's k, each with the error |fine − coarse|.
    pub fn evaluate(&self, spectrum: &LinearSpectrum) -> Gamma2Terms {
        let samples = self.lattice.sample(spectrum);
        let (p_fine, p_coarse) = (
            self.fine.radial_spectrum(&self.lattice, &samples),
            self.coarse.radial_spectrum(&self.lattice, &samples),
        );
        let rows: Vec<[[Estimate; 3]; 2]> = (0..self.len())
            .into_par_iter()
            .map(|i| {
                let a = self.fine.evaluate(i, &self.lattice, &samples, &p_fine);
                let b = self.coarse.evaluate(i, &self.lattice, &samples, &p_coarse);
                estimates(a, b, [[0.0; 3]; 2])
            })
            .collect();
        Gamma2Terms::from_rows(&rows, None)
    }
}

/// [P24, PΓ2] of the three pairs from the fine and coarse layouts' values, with the error
/// |fine − coarse| (at least [`ERROR_FLOOR`] of the value) plus `extra`.
fn estimates(
    fine: [[f64; 3]; 2],
    coarse: [[f64; 3]; 2],
    extra: [[f64; 3]; 2],
) -> [[Estimate; 3]; 2] {
    std::array::from_fn(|t| {
        std::array::from_fn(|m| {
            let (a, b) = (fine[t][m], coarse[t][m]);
            Estimate::new(a, (a - b).abs().max(ERROR_FLOOR * a.abs()) + extra[t][m])
        })
    })
}

impl Gamma2Terms {
    /// The terms from their per-k [P24, PΓ2] rows.
    fn from_rows(rows: &[[[Estimate; 3]; 2]], basis_residual: Option<f64>) -> Self {
        let column = |t: usize| {
            ByPair::from_fn(|pair: Pair| rows.iter().map(|r| r[t][pair as usize]).collect())
        };
        Self {
            p24: column(0),
            p_gamma2: column(1),
            basis_residual,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A layout with 1.5–2 times the points in every direction and no tail growth.
    const REFERENCE: Layout = Layout {
        outer: 6,
        radial: 6,
        angular: 10,
        angular_far: 8,
        width: 0.3,
    };

    #[test]
    fn the_default_layout_agrees_with_a_refined_one_within_its_error() {
        let spectrum = LinearSpectrum::gm2012(0.0).unwrap();
        let k = [0.02, 0.1, 0.25];
        let lattice = Lattice::new(1e-4, 50.0, 0.01);
        let samples = lattice.sample(&spectrum);
        let evaluate = |layout: Layout| -> Vec<[[f64; 3]; 2]> {
            let start = std::time::Instant::now();
            let nodes =
                Nodes::layout(&k, &lattice, layout).with_weights(&k, &lattice, layout, &|_| {});
            let p_r = nodes.radial_spectrum(&lattice, &samples);
            println!(
                "{layout:?}: {} outer, {} radial nodes, {:?}",
                nodes.outer.len(),
                p_r.len(),
                start.elapsed()
            );
            (0..k.len())
                .map(|i| nodes.evaluate(i, &lattice, &samples, &p_r))
                .collect()
        };
        let (fine, coarse, reference) = (evaluate(FINE), evaluate(COARSE), evaluate(REFERENCE));
        for i in 0..k.len() {
            for t in 0..2 {
                for m in 0..3 {
                    let (a, b, r) = (fine[i][t][m], coarse[i][t][m], reference[i][t][m]);
                    let (error, estimate) = ((a - r).abs() / r.abs(), (a - b).abs() / r.abs());
                    println!(
                        "k = {} term {t} pair {m}: {error:.1e} (estimate {estimate:.1e})",
                        k[i]
                    );
                    assert!(
                        error < 1e-4 && error < estimate,
                        "k = {} term {t} pair {m}: {a} {b} {r}",
                        k[i]
                    );
                }
            }
        }
    }
}
