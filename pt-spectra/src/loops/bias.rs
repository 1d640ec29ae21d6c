//! The 1-loop operators of the galaxy bias expansion (McDonald & Roy 2009, arXiv:0902.0991; Saito et al.
//! 2014, arXiv:1405.1447), with FAST-PT's names and normalisations (its `one_loop_dd_bias_b3nl`),
//! and their velocity counterparts, as cosmology-independent plans.
//!
//! With ∫ = ∫d³q/(2π)³, P = P(q), P' = P(|k − q|), and the kernels of (q, k − q):
//!   Pd1d2 = 2∫ F₂ P P',  Pd2d2 = 2∫ P P',  Pd1s2 = 2∫ F₂ S₂ P P',  Pd2s2 = 2∫ S₂ P P',
//!   Ps2s2 = 2∫ S₂² P P',  Pt1d2 = 2∫ G₂ P P',  Pt1s2 = 2∫ G₂ S₂ P P',
//!   sig3nl = P_lin(k) ∫ P(q) (4/3)[D₂(−q, k) S₂(q, k − q) + 8/63] = (64/315) σ₃²(k) P_lin(k),
//! S₂(q₁, q₂) = (q₁·q₂)²/(q₁²q₂²) − 1/3, D₂(q₁, q₂) = (2/7)[(q₁·q₂)²/(q₁²q₂²) − 1]. The galaxy spectra
//! (Saito et al. 2014 eq. 13–14, FAST-PT's convention, b3nl the non-local cubic bias) are
//!   P_gg = b1² P_δδ + b1 b2 Pd1d2 + ¼ b2² Pd2d2 + b1 bs Pd1s2 + ½ b2 bs Pd2s2 + ¼ bs² Ps2s2
//!          + 2 b1 b3nl sig3nl,
//!   P_gm = b1 P_δδ + ½ b2 Pd1d2 + ½ bs Pd1s2 + b3nl sig3nl,
//! and the velocity cross-spectrum of TNS with nonlinear bias (Beutler et al. 2017)
//!   P_gθ = b1 P_δθ + ½ b2 Pt1d2 + ½ bs Pt1s2 + b3nl sig3nl.
//!
//! Values are FAST-PT's, no constant subtracted: as k → 0, Pd2d2 → 2σ₄², Pd2s2 → (4/3)σ₄²,
//! Ps2s2 → (8/9)σ₄² with σ₄² = ∫ P(q)² (4.0345e3 (Mpc/h)³ for gm2012 at z = 0), constants of the
//! stochastic term that analyses subtract or absorb into the shot noise; Pd1d2, Pd1s2, Pt1d2, Pt1s2
//! and sig3nl vanish there.
//!
//! Numerics: the pair terms on the node sets of P22 (`loops::p22`, the same half p ≥ q of the
//! (q, p) plane, every kernel being symmetric), sig3nl with the angle done analytically,
//!   sig3nl = P_lin(k) k³/(2π²) ∫ dr r² P(kr) A(r),
//!   A(r) = [4r⁵(11 − 3r²) + 44r³ − 12r + 6(r² − 1)⁴ ln|(1 + r)/(1 − r)|]/(504 r⁵),
//! A(0) = 64/315, A(1/r) = r² A(r), on the lattice like P13 (a series for r < 0.3 and, through the
//! symmetry, for r > 1/0.3, where the closed form cancels). Errors as the 1-loop terms: the half-
//! resolution rule's difference, floored at `p22_error_floor` of each pair term.

use super::lattice::{add_product_weights, Lattice};
use super::one_loop::{validate_grid, COARSE_ORDER_DROP};
use super::p22::{f2_g2, Layout, PairNodes};
use super::Estimate;
use crate::error::Result;
use crate::integrate::legendre_nodes;
use crate::linalg::dot;
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The names of the pair terms, in the order of [`BiasTerms::pairs`].
pub const PAIR_NAMES: [&str; 7] = [
    "Pd1d2", "Pd2d2", "Pd1s2", "Pd2s2", "Ps2s2", "Pt1d2", "Pt1s2",
];

/// Below this r the series of A(r) is used (and above 1/`SERIES_R` through A(1/r) = r² A(r)).
const SERIES_R: f64 = 0.3;

/// A(r): coefficients of r^{2i} for r → 0 (exact rationals 64/d).
const A_SMALL: [f64; 14] = [
    64.0 / 315.0,
    -64.0 / 735.0,
    64.0 / 6615.0,
    64.0 / 72765.0,
    64.0 / 315315.0,
    64.0 / 945945.0,
    64.0 / 2297295.0,
    64.0 / 4849845.0,
    64.0 / 9258795.0,
    64.0 / 16380945.0,
    64.0 / 27301575.0,
    64.0 / 43361325.0,
    64.0 / 66183075.0,
    64.0 / 97698825.0,
];

/// The angular average A(r), r = q/k, of the sig3nl kernel (4/3)[D₂(−q, k)S₂(q, k − q) + 8/63] (module
/// docs).
pub fn sig3nl_kernel(r: f64) -> f64 {
    if r > 1.0 / SERIES_R {
        return sig3nl_kernel(1.0 / r) / (r * r);
    }
    if r < SERIES_R {
        let r2 = r * r;
        return A_SMALL.iter().rev().fold(0.0, |acc, &c| acc * r2 + c);
    }
    if r == 1.0 {
        return (4.0 * 8.0 + 44.0 - 12.0) / 504.0;
    }
    let r2 = r * r;
    let log = ((1.0 + r) / (1.0 - r).abs()).ln();
    let r5 = r2 * r2 * r;
    (4.0 * r5 * (11.0 - 3.0 * r2) + 44.0 * r2 * r - 12.0 * r + 6.0 * (r2 - 1.0).powi(4) * log)
        / (504.0 * r5)
}

/// The seven pair kernels [F₂, 1, F₂S₂, S₂, S₂², G₂, G₂S₂] of (q, k − q) from k², q², p² = |k − q|².
#[inline]
fn pair_kernels(k2: f64, q2: f64, p2: f64) -> [f64; 7] {
    let [f, g] = f2_g2(k2, q2, p2);
    let c = 0.5 * (k2 - q2 - p2);
    let s = c * c / (q2 * p2) - 1.0 / 3.0;
    [f, 1.0, f * s, s, s * s, g, g * s]
}

/// The bias terms of one k grid, each with its estimated numerical error.
#[derive(Debug, Clone, PartialEq)]
pub struct BiasTerms {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// The pair terms [(Mpc/h)³], in the order of [`PAIR_NAMES`], each a value per k.
    pub pairs: [Vec<Estimate>; 7],
    /// sig3nl [(Mpc/h)³] (P_lin(k) included).
    pub sig3nl: Vec<Estimate>,
    /// σ₄² = ∫d³q/(2π)³ P(q)² [(Mpc/h)³], whose multiples are the k → 0 limits (module docs).
    pub sigma4: Estimate,
}

impl BiasTerms {
    /// The pair term `name` (one of [`PAIR_NAMES`]).
    pub fn pair(&self, name: &str) -> Option<&[Estimate]> {
        PAIR_NAMES
            .iter()
            .position(|&n| n == name)
            .map(|i| self.pairs[i].as_slice())
    }
}

/// Weights of one lattice (fine or half-resolution).
#[derive(Debug, Clone)]
struct Rule {
    lattice: Lattice,
    /// Per k: lattice weights of sig3nl/P_lin(k).
    sig3nl: Vec<Vec<f64>>,
    /// Lattice weights of σ₄² (applied to P²).
    sigma4: Vec<f64>,
    pairs: PairNodes<7>,
}

impl Rule {
    fn new(ks: &[f64], lattice: Lattice, precision: &Precision, drop: usize) -> Self {
        let (nodes, weights) = legendre_nodes(precision.p13_cell_order);
        let rule = (nodes.as_slice(), weights.as_slice());
        let layout = Layout::new(precision, drop);
        // The half p ≥ q counts twice (see `P22Nodes::p22`), and every pair term is 2∫…
        let pairs = PairNodes::new(ks, &lattice, &layout, &|k, q, p, measure| {
            let c = measure / (PI * PI);
            pair_kernels(k * k, q * q, p * p).map(|v| c * v)
        });
        let sig3nl = ks
            .par_iter()
            .map(|&k| {
                let (a, b) = (lattice.x0, lattice.x_end());
                let split = k.ln().clamp(a, b);
                let mut w = [vec![0.0; lattice.len]];
                for (lo, hi) in [(a, split), (split, b)] {
                    if hi > lo {
                        add_product_weights(&lattice, &mut w, (lo, hi), rule, |x| {
                            let q = x.exp();
                            [q * q * q / (2.0 * PI * PI) * sig3nl_kernel(q / k)]
                        });
                    }
                }
                let [w] = w;
                w
            })
            .collect();
        // σ₄² = (1/2π²) ∫ dx q³ P²: weights of the interpolant of P² (a smooth function as P is).
        let mut s4 = [vec![0.0; lattice.len]];
        add_product_weights(
            &lattice,
            &mut s4,
            (lattice.x0, lattice.x_end()),
            rule,
            |x| [(3.0 * x).exp() / (2.0 * PI * PI)],
        );
        let [sigma4] = s4;
        Self {
            lattice,
            sig3nl,
            sigma4,
            pairs,
        }
    }

    /// The seven pair terms at k index `i` from the lattice `samples`.
    fn pairs(&self, i: usize, samples: &[f64]) -> [f64; 7] {
        let (mut start, outer) = self.pairs.ranges(i);
        let mut total = [0.0; 7];
        for o in outer {
            let end = self.pairs.outer_end[o] as usize;
            let mut acc = [0.0; 7];
            let nodes = self.pairs.inner_b[start..end]
                .iter()
                .zip(&self.pairs.inner_l[start..end])
                .zip(&self.pairs.inner_w[start..end]);
            for ((&b, l), w) in nodes {
                let s = &samples[b as usize..b as usize + 4];
                let l = l.map(f64::from);
                let pp = (l[0] * s[0] + l[1] * s[1]) + (l[2] * s[2] + l[3] * s[3]);
                for (a, w) in acc.iter_mut().zip(w) {
                    *a += f64::from(*w) * pp;
                }
            }
            let pq = self.lattice.interpolate(samples, self.pairs.outer_u[o]);
            for (t, a) in total.iter_mut().zip(acc) {
                *t += pq * a;
            }
            start = end;
        }
        total
    }
}

/// The plan of the bias terms on a fixed k grid: all weights, independent of the linear spectrum.
///
/// ```
/// use pt_spectra::{linear::LinearSpectrum, loops::bias::BiasPlan, precision::Precision};
/// let p = LinearSpectrum::gm2012(0.0)?;
/// let t = BiasPlan::new(&[1e-3, 0.1], &Precision::fast())?.evaluate(&p);
/// // Pd2d2 tends to 2σ₄² as k → 0.
/// let (pd2d2, s4) = (t.pair("Pd2d2").unwrap()[0].value, t.sigma4.value);
/// assert!((pd2d2 / (2.0 * s4) - 1.0).abs() < 1e-3, "{pd2d2} {s4}");
/// # Ok::<(), pt_spectra::error::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct BiasPlan {
    k: Vec<f64>,
    precision: Precision,
    fine: Rule,
    coarse: Rule,
}

/// Bytes per output k of the plan at the default node density (7 f32 weights per P22 node).
const BYTES_PER_K: f64 = 0.6e6;

impl BiasPlan {
    /// The estimated memory of a plan on `nk` wavenumbers with `precision` \[bytes\] (its rules at
    /// `BYTES_PER_K` per k, scaled with the node density), which [`new`](Self::new) checks against
    /// the limit before it allocates.
    pub fn memory_estimate(nk: usize, precision: &Precision) -> f64 {
        BYTES_PER_K * crate::memory::node_density(precision) * nk as f64
    }

    /// The plan for wavenumbers `k` [h/Mpc] with the P22 and P13 settings of `precision`.
    ///
    /// # Errors
    /// As [`crate::loops::OneLoopPlan::new`]; [`crate::error::Error::MemoryLimit`] above the memory
    /// limit.
    pub fn new(k: &[f64], precision: &Precision) -> Result<Self> {
        validate_grid(k, precision)?;
        crate::memory::check(
            crate::memory::PROCESS + Self::memory_estimate(k.len(), precision),
            precision,
            &format!("the bias plan on {} k", k.len()),
        )?;
        let lattice = Lattice::new(precision.q_min, precision.q_max, precision.lattice_step);
        let coarse_lattice = lattice.coarse();
        let (coarse, fine) = rayon::join(
            || Rule::new(k, coarse_lattice, precision, COARSE_ORDER_DROP),
            || Rule::new(k, lattice, precision, 0),
        );
        Ok(Self {
            k: k.to_vec(),
            precision: precision.clone(),
            fine,
            coarse,
        })
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.k
    }

    /// The precision the plan was made with.
    pub fn precision(&self) -> &Precision {
        &self.precision
    }

    /// Every bias term of `spectrum` (over the plan's q range, through the spectrum's power-law
    /// extrapolation outside its table), k after k over rayon's threads.
    pub fn evaluate(&self, spectrum: &LinearSpectrum) -> BiasTerms {
        let fine = self.fine.lattice.sample(spectrum);
        let coarse: Vec<f64> = fine.iter().step_by(2).copied().collect();
        let floor = self.precision.p22_error_floor;
        let rows: Vec<([Estimate; 7], Estimate)> = (0..self.k.len())
            .into_par_iter()
            .with_min_len(4)
            .map(|i| {
                let (a, b) = (self.fine.pairs(i, &fine), self.coarse.pairs(i, &coarse));
                let pairs = std::array::from_fn(|j| {
                    Estimate::new(a[j], (a[j] - b[j]).abs().max(floor * a[j].abs()))
                });
                let p = spectrum.eval(self.k[i]);
                let s = dot(&self.fine.sig3nl[i], &fine);
                let s_coarse = dot(&self.coarse.sig3nl[i], &coarse);
                (pairs, Estimate::new(p * s, (p * (s - s_coarse)).abs()))
            })
            .collect();
        let squares = |v: &[f64]| v.iter().map(|p| p * p).collect::<Vec<f64>>();
        let s4 = dot(&self.fine.sigma4, &squares(&fine));
        let s4_coarse = dot(&self.coarse.sigma4, &squares(&coarse));
        let mut pairs: [Vec<Estimate>; 7] = Default::default();
        let mut sig3nl = Vec::with_capacity(rows.len());
        for (row, s) in rows {
            for (column, e) in pairs.iter_mut().zip(row) {
                column.push(e);
            }
            sig3nl.push(s);
        }
        BiasTerms {
            k: self.k.clone(),
            pairs,
            sig3nl,
            sigma4: Estimate::new(s4, (s4 - s4_coarse).abs()),
        }
    }
}

/// The bias parameters of the real-space galaxy spectra in FAST-PT's convention (module docs): b1,
/// b2, bs (= b_s², (bs/2)s²) and b3nl. The faces take velocileptors' ([`crate::bias::BiasParams`],
/// converted by `From`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GalaxyBias {
    /// Linear bias b1.
    pub b1: f64,
    /// Second-order local bias b2.
    pub b2: f64,
    /// Tidal bias b_s² (FAST-PT's bs).
    pub bs: f64,
    /// Non-local cubic bias b3nl.
    pub b3nl: f64,
}

impl From<crate::bias::BiasParams> for GalaxyBias {
    /// FAST-PT's values of a bias given in velocileptors' convention ([`crate::bias`]).
    fn from(b: crate::bias::BiasParams) -> Self {
        let [b1, b2, bs, b3nl] = b.in_convention(crate::bias::BiasConvention::FastPt);
        Self { b1, b2, bs, b3nl }
    }
}

impl GalaxyBias {
    /// P_gg and P_gm at k index `i` from the matter spectrum `p_dd` of any model and the bias terms.
    pub fn spectra(&self, i: usize, p_dd: Estimate, t: &BiasTerms) -> [Estimate; 2] {
        let Self { b1, b2, bs, b3nl } = *self;
        let [d1d2, d2d2, d1s2, d2s2, s2s2, _, _] = std::array::from_fn(|j| t.pairs[j][i]);
        let s3 = t.sig3nl[i];
        let gg = p_dd * (b1 * b1)
            + d1d2 * (b1 * b2)
            + d2d2 * (0.25 * b2 * b2)
            + d1s2 * (b1 * bs)
            + d2s2 * (0.5 * b2 * bs)
            + s2s2 * (0.25 * bs * bs)
            + s3 * (2.0 * b1 * b3nl);
        let gm = p_dd * b1 + d1d2 * (0.5 * b2) + d1s2 * (0.5 * bs) + s3 * b3nl;
        [gg, gm]
    }

    /// P_gθ at k index `i` from the matter P_δθ of any model (Beutler et al. 2017's P_gδ,θ in this
    /// normalisation): b1 P_δθ + ½ b2 Pt1d2 + ½ bs Pt1s2 + b3nl sig3nl.
    pub fn velocity(&self, i: usize, p_dt: Estimate, t: &BiasTerms) -> Estimate {
        let (t1d2, t1s2) = (t.pairs[5][i], t.pairs[6][i]);
        p_dt * self.b1 + t1d2 * (0.5 * self.b2) + t1s2 * (0.5 * self.bs) + t.sig3nl[i] * self.b3nl
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A(r) against a direct Gauss–Legendre average of (4/3)[D₂S₂ + 8/63] over the angle.
    #[test]
    fn sig3nl_kernel_is_the_angular_average() {
        let (x, w) = legendre_nodes(64);
        for r in [
            0.05, 0.2, 0.29, 0.31, 0.5, 0.9, 1.0, 1.1, 2.0, 3.3, 3.4, 10.0, 100.0,
        ] {
            // Split the angle at μ = 1 − (1 − r)²/... : 64 nodes in each half are enough away from r = 1.
            let mut direct = 0.0;
            for (lo, hi) in [(-1.0, 0.0), (0.0, 0.9), (0.9, 0.99), (0.99, 1.0)] {
                let (m, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
                for (&xi, &wi) in x.iter().zip(&w) {
                    let mu: f64 = m + h * xi;
                    let s2 = (mu - r).powi(2) / (1.0 + r * r - 2.0 * r * mu) - 1.0 / 3.0;
                    let d2 = 2.0 / 7.0 * (mu * mu - 1.0);
                    direct += 0.5 * h * wi * 4.0 / 3.0 * (d2 * s2 + 8.0 / 63.0);
                }
            }
            let a = sig3nl_kernel(r);
            assert!(
                (a - direct).abs() < 1e-9 * direct.abs(),
                "r = {r}: {a} vs {direct}"
            );
        }
        assert!((sig3nl_kernel(1e-6) - 64.0 / 315.0).abs() < 1e-12);
    }

    #[test]
    fn pair_kernels_are_the_bias_operators() {
        // Orthogonal q ⟂ k − q: S₂ = −1/3, F₂ = 5/7, G₂ = 3/7.
        let (q2, p2) = (0.3_f64.powi(2), 0.4_f64.powi(2));
        let k = pair_kernels(q2 + p2, q2, p2);
        let s = -1.0 / 3.0;
        let want = [
            5.0 / 7.0,
            1.0,
            5.0 / 7.0 * s,
            s,
            s * s,
            3.0 / 7.0,
            3.0 / 7.0 * s,
        ];
        for (a, b) in k.iter().zip(want) {
            assert!((a - b).abs() < 1e-15, "{k:?}");
        }
    }
}
