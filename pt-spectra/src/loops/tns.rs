//! The TNS correction terms A(k, μ) and B(k, μ) of Taruya, Nishimichi & Saito (2010, PRD 82, 063522) at
//! leading order (linear spectrum, tree-level bispectrum), decomposed once per k into coefficients of
//! μ^{2n} f^m, so that any (f, b) costs a polynomial evaluation.
//!
//! Definitions (θ ≡ −∇·v/(aHf), so θ_lin = δ_lin; bias b; the line of sight ẑ, μ = k̂·ẑ):
//! * A = kμf ∫d³q/(2π)³ (q_z/q²) [B_σ(q, k−q, −k) − B_σ(q, k, −k−q)], where
//!   ⟨θ(k₁) X(k₂) X(k₃)⟩ = (2π)³δ_D(k₁+k₂+k₃) B_σ(k₁, k₂, k₃), X = bδ + fμ²θ. Substituting q → −q in the
//!   second term and using the parity and the k₂ ↔ k₃ symmetry of B_σ, both terms are equal:
//!   A = 2kμf ∫ (q_z/q²) B_σ(q, k−q, −k). At tree level, with m_v = v̂·ẑ and P_v = P_lin(|v|),
//!   B_σ(k₁,k₂,k₃)/2 = G₂(k₂,k₃)(b + f m₂²)(b + f m₃²) P₂P₃ + [bF₂(k₁,k₃) + f m₂² G₂(k₁,k₃)](b + f m₃²) P₁P₃
//!   + [bF₂(k₁,k₂) + f m₃² G₂(k₁,k₂)](b + f m₂²) P₁P₂.
//! * B = (kμf)² ∫d³q/(2π)³ F(q) F(k−q), F(q) = (q_z/q²)[b P_δθ(q) + f m_q² P_θθ(q)].
//!
//! Both scale as A = b³A(k, μ; f/b, b = 1), B = b⁴B(k, μ; f/b, b = 1), and at b = 1
//! A = Σ_{m=1..3} Σ_{n=1..m} a_{nm}(k) μ^{2n} f^m, B = Σ_{m=2..4} Σ_{n=1..m} b_{nm}(k) μ^{2n} f^m (these are
//! the only powers that occur). Every line-of-sight cosine is linear in μ and w = √(1−μ²) cos φ, φ the
//! azimuth of q about k: m_q = xμ + sw, m_{k−q} = [(k − qx)μ − qsw]/|k−q| with x = k̂·q̂, s = √(1−x²). The
//! azimuthal average ⟨w^{2j}⟩ = (1−μ²)^j (2j−1)!!/(2j)!! turns each integrand into a polynomial in μ², so
//! every coefficient is a 2-D integral over (q, |k−q|) with a cosmology-independent kernel. The integrals
//! use the P22 nodes (module `p22`) on the half |k−q| ≥ q and their mirror images q ↔ k − q, so each node
//! carries three kinds of products, P(q)P(|k−q|), P(k)P(|k−q|) and P(k)P(q).
//!
//! The error of each coefficient is the change with the half-resolution rule (as for P22), plus a floor
//! of [`Precision::p22_error_floor`] times its magnitude.
//!
//! [`Precision::p22_error_floor`]: crate::precision::Precision::p22_error_floor

use super::lattice::Lattice;
use super::p22::{f2_g2, Layout, PairNodes};
use super::Estimate;
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Number of (n, m) coefficients of A: m = 1..3, n = 1..m.
pub(crate) const A_LEN: usize = 6;
/// Number of (n, m) coefficients of B: m = 2..4, n = 1..m.
pub(crate) const B_LEN: usize = 9;
/// Weights per node: A and B for P(q)P(p), then A for P(k)P(p), then A for P(k)P(q).
pub(crate) const WEIGHTS: usize = 2 * A_LEN + A_LEN + B_LEN;

/// Index of μ^{2n} f^m in the packed A coefficients.
const fn a_index(n: usize, m: usize) -> usize {
    m * (m - 1) / 2 + n - 1
}

/// Index of μ^{2n} f^m in the packed B coefficients.
const fn b_index(n: usize, m: usize) -> usize {
    (m - 2) * (m + 1) / 2 + n - 1
}

/// The leading-order TNS coefficients at one k [(Mpc/h)^3], for b = 1.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TnsCoefficients {
    /// Coefficients of μ^{2n} f^m of A, packed (m = 1..3, n = 1..m); see [`a`](Self::a).
    a: [Estimate; A_LEN],
    /// Coefficients of μ^{2n} f^m of B, packed (m = 2..4, n = 1..m); see [`b`](Self::b).
    b: [Estimate; B_LEN],
}

impl TnsCoefficients {
    /// The coefficients from their packed arrays (A: m = 1..3, n = 1..m; B: m = 2..4, n = 1..m).
    pub(crate) fn from_packed(a: [Estimate; A_LEN], b: [Estimate; B_LEN]) -> Self {
        Self { a, b }
    }

    /// The coefficient a_{nm} of μ^{2n} f^m in A (b = 1); zero outside 1 ≤ n ≤ m ≤ 3.
    pub fn a(&self, n: usize, m: usize) -> Estimate {
        if (1..=3).contains(&m) && (1..=m).contains(&n) {
            self.a[a_index(n, m)]
        } else {
            Estimate::default()
        }
    }

    /// The coefficient b_{nm} of μ^{2n} f^m in B (b = 1); zero outside 1 ≤ n ≤ m, 2 ≤ m ≤ 4.
    pub fn b(&self, n: usize, m: usize) -> Estimate {
        if (2..=4).contains(&m) && (1..=m).contains(&n) {
            self.b[b_index(n, m)]
        } else {
            Estimate::default()
        }
    }

    /// The coefficients of μ⁰, μ², …, μ⁸ of A(k, μ) for growth rate `f` and bias `b`
    /// (A = b³ Σ a_{nm} μ^{2n} (f/b)^m), and the bound on their numerical errors.
    pub fn a_polynomial(&self, f: f64, b: f64) -> ([f64; 5], [f64; 5]) {
        polynomial(1..=3, 3, f, b, |n, m| self.a(n, m))
    }

    /// The coefficients of μ⁰, μ², …, μ⁸ of B(k, μ) for growth rate `f` and bias `b`
    /// (B = b⁴ Σ b_{nm} μ^{2n} (f/b)^m), and the bound on their numerical errors.
    pub fn b_polynomial(&self, f: f64, b: f64) -> ([f64; 5], [f64; 5]) {
        polynomial(2..=4, 4, f, b, |n, m| self.b(n, m))
    }
}

/// Σ_m Σ_n c(n, m) μ^{2n} f^m b^{order − m} as coefficients of μ^{2n}, with the summed errors.
fn polynomial(
    powers: std::ops::RangeInclusive<usize>,
    order: usize,
    f: f64,
    b: f64,
    c: impl Fn(usize, usize) -> Estimate,
) -> ([f64; 5], [f64; 5]) {
    let (mut value, mut error) = ([0.0; 5], [0.0; 5]);
    for m in powers {
        let scale = f.powi(m as i32) * b.powi((order - m) as i32);
        for n in 1..=m {
            let e = c(n, m);
            value[n] += scale * e.value;
            error[n] += scale.abs() * e.error;
        }
    }
    (value, error)
}

/// The TNS coefficients on a k grid.
#[derive(Debug, Clone, PartialEq)]
pub struct TnsTerms {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// The linear spectrum at k [(Mpc/h)^3].
    pub p_lin: Vec<f64>,
    /// The coefficients at each k.
    pub coefficients: Vec<TnsCoefficients>,
    /// The spectrum's projection residual if the coefficients come from the basis tensors
    /// ([`super::basis::TnsBasis`]); `None` for the direct integrals.
    pub basis_residual: Option<f64>,
    /// Δ [(Mpc/h)²] if the spectrum was projected cut below the soft modes ([`super::basis::soft`]).
    pub basis_soft: Option<f64>,
}

/// A homogeneous polynomial Σ_i c_i μ^{d−i} w^i of degree d = `c.len()` − 1 in μ and w.
#[derive(Debug, Clone, PartialEq)]
struct Form(Vec<f64>);

impl Form {
    /// aμ + bw.
    fn linear(a: f64, b: f64) -> Self {
        Self(vec![a, b])
    }

    fn mul(&self, other: &Self) -> Self {
        let mut c = vec![0.0; self.0.len() + other.0.len() - 1];
        for (i, a) in self.0.iter().enumerate() {
            for (j, b) in other.0.iter().enumerate() {
                c[i + j] += a * b;
            }
        }
        Self(c)
    }

    fn add(&self, other: &Self) -> Self {
        assert_eq!(self.0.len(), other.0.len(), "forms of different degree");
        Self(self.0.iter().zip(&other.0).map(|(a, b)| a + b).collect())
    }

    /// The average over φ (w = √(1−μ²) cos φ) as coefficients of μ^{2n}, n = 0..4 (degree d ≤ 8,
    /// even): ⟨w^{2j}⟩ = (1−μ²)^j C(2j, j)/4^j.
    fn average(&self) -> [f64; 5] {
        const COS_MOMENTS: [f64; 5] = [1.0, 0.5, 0.375, 0.3125, 0.2734375];
        let d = self.0.len() - 1;
        debug_assert!(d.is_multiple_of(2) && d <= 8);
        let mut out = [0.0; 5];
        for j in 0..=d / 2 {
            let c = self.0[2 * j] * COS_MOMENTS[j];
            // μ^{d−2j} (1−μ²)^j = Σ_l C(j, l) (−1)^l μ^{d−2j+2l}
            let mut binomial = 1.0;
            for l in 0..=j {
                out[d / 2 - j + l] += c * binomial;
                binomial *= -((j - l) as f64) / (l + 1) as f64;
            }
        }
        out
    }
}

/// For m = 1, 2, 3: the (polynomial in μ², kernel value) pairs whose products make the f^m part.
type ByPower = [Vec<([f64; 5], f64)>; 3];

/// The A weights of one (q, p = |k − q|) point, per product [P(q)P(p), P(k)P(p), P(k)P(q)], and the B
/// weights (all P(q)P(p)), for the quadrature weight `c` of ∫d³q/(2π)³ ⟨·⟩_φ.
fn point_weights(k: f64, q: f64, p: f64, c: f64) -> ([[f64; A_LEN]; 3], [f64; B_LEN]) {
    let (k2, q2, p2) = (k * k, q * q, p * p);
    let x = ((k2 + q2 - p2) / (2.0 * k * q)).clamp(-1.0, 1.0);
    let s = (1.0 - x * x).sqrt();
    let mu = Form::linear(1.0, 0.0);
    let mq = Form::linear(x, s);
    let mp = Form::linear((k - q * x) / p, -q * s / p);
    let mp2 = mp.mul(&mp);
    let mu_mq = mu.mul(&mq);
    let mu3_mq = mu_mq.mul(&mu).mul(&mu);
    // ⟨μ m_q⟩, ⟨μ m_q m_p²⟩, ⟨μ³ m_q⟩, ⟨μ³ m_q m_p²⟩
    let avg1 = mu_mq.average();
    let avg2 = mu_mq.mul(&mp2).average();
    let avg3 = mu3_mq.average();
    let avg4 = mu3_mq.mul(&mp2).average();

    // G₂(k−q, −k), [F₂, G₂](q, −k), [F₂, G₂](q, k−q): f2_g2 takes |sum|², |a|², |b|².
    let g2a = f2_g2(q2, p2, k2)[1];
    let [f2b, g2b] = f2_g2(p2, q2, k2);
    let [f2c, g2c] = f2_g2(k2, q2, p2);
    let a_scale = 4.0 * k / q * c;
    let mut a = [[0.0; A_LEN]; 3];
    // f¹, f², f³ parts of 4kμf (m_q/q) × [G₂ₐ(1+f m_p²)(1+fμ²), (F₂b + f m_p² G₂b)(1+fμ²),
    // (F₂c + fμ² G₂c)(1+f m_p²)], for the products P(q)P(p), P(k)P(p), P(k)P(q).
    let parts: [ByPower; 3] = [
        [
            vec![(avg1, f2c)],
            vec![(avg2, f2c), (avg3, g2c)],
            vec![(avg4, g2c)],
        ],
        [
            vec![(avg1, g2a)],
            vec![(avg2, g2a), (avg3, g2a)],
            vec![(avg4, g2a)],
        ],
        [
            vec![(avg1, f2b)],
            vec![(avg2, g2b), (avg3, f2b)],
            vec![(avg4, g2b)],
        ],
    ];
    for (out, product) in a.iter_mut().zip(&parts) {
        for (m, terms) in (1..=3).zip(product) {
            for (poly, scalar) in terms {
                for n in 1..=m {
                    out[a_index(n, m)] += a_scale * scalar * poly[n];
                }
            }
        }
    }

    let b_scale = k2 / (q * p) * c;
    let mu2_mq_mp = mu.mul(&mu).mul(&mq).mul(&mp);
    let (mq2, mq3) = (mq.mul(&mq), mq.mul(&mq).mul(&mq));
    let mp3 = mp2.mul(&mp);
    let b_polys = [
        mu2_mq_mp.average(),
        mu2_mq_mp.mul(&mq2.add(&mp2)).average(),
        mu.mul(&mu).mul(&mq3).mul(&mp3).average(),
    ];
    let mut b = [0.0; B_LEN];
    for (m, poly) in (2..=4).zip(b_polys) {
        for n in 1..=m {
            b[b_index(n, m)] = b_scale * poly[n];
        }
    }
    (a, b)
}

/// The weights of a node of the half p ≥ q and of its mirror point (q ↔ p, m_q ↔ m_p), packed as
/// [A of P(q)P(p), B of P(q)P(p), A of P(k)P(p), A of P(k)P(q)].
fn node_weights(k: f64, q: f64, p: f64, measure: f64) -> [f64; WEIGHTS] {
    let c = measure / (4.0 * PI * PI);
    let (a, b) = point_weights(k, q, p, c);
    let (a_mirror, b_mirror) = point_weights(k, p, q, c);
    let mut w = [0.0; WEIGHTS];
    for i in 0..A_LEN {
        w[i] = a[0][i] + a_mirror[0][i];
        // The mirror's P(k)P(q′) is P(k)P(p), and its P(k)P(p′) is P(k)P(q).
        w[A_LEN + B_LEN + i] = a[1][i] + a_mirror[2][i];
        w[2 * A_LEN + B_LEN + i] = a[2][i] + a_mirror[1][i];
    }
    for i in 0..B_LEN {
        w[A_LEN + i] = b[i] + b_mirror[i];
    }
    w
}

/// The nodes of one resolution.
#[derive(Debug, Clone)]
pub(crate) struct Rule {
    pub lattice: Lattice,
    pub nodes: PairNodes<WEIGHTS>,
}

impl Rule {
    /// Packed [A, B] coefficients at k index i from the lattice samples, with P(k) = `p_k`.
    fn coefficients(&self, i: usize, samples: &[f64], p_k: f64) -> [f64; A_LEN + B_LEN] {
        const PQ: usize = A_LEN + B_LEN;
        let nodes = &self.nodes;
        let (mut start, outer) = nodes.ranges(i);
        let (mut pq_pp, mut pk_pp, mut pk_pq) = ([0.0; PQ], [0.0; A_LEN], [0.0; A_LEN]);
        for o in outer {
            let end = nodes.outer_end[o] as usize;
            let (mut acc_pp, mut acc_kp, mut acc_kq) = ([0.0; PQ], [0.0; A_LEN], [0.0; A_LEN]);
            for j in start..end {
                let b = nodes.inner_b[j] as usize;
                let (s, l) = (&samples[b..b + 4], nodes.inner_l[j].map(f64::from));
                let pp = (l[0] * s[0] + l[1] * s[1]) + (l[2] * s[2] + l[3] * s[3]);
                let w = &nodes.inner_w[j];
                for t in 0..PQ {
                    acc_pp[t] += f64::from(w[t]) * pp;
                }
                for t in 0..A_LEN {
                    acc_kp[t] += f64::from(w[PQ + t]) * pp;
                    acc_kq[t] += f64::from(w[PQ + A_LEN + t]);
                }
            }
            let pq = self.lattice.interpolate(samples, nodes.outer_u[o]);
            for t in 0..PQ {
                pq_pp[t] += pq * acc_pp[t];
            }
            for t in 0..A_LEN {
                pk_pp[t] += acc_kp[t];
                pk_pq[t] += pq * acc_kq[t];
            }
            start = end;
        }
        for t in 0..A_LEN {
            pq_pp[t] += p_k * (pk_pp[t] + pk_pq[t]);
        }
        pq_pp
    }
}

/// A plan for the TNS coefficients on a fixed k grid: cosmology-independent node weights, built once.
///
/// ```
/// use pt_spectra::{linear::LinearSpectrum, loops::TnsPlan, precision::Precision};
/// let p = LinearSpectrum::gm2012(0.0)?;
/// let plan = TnsPlan::new(&[0.1], &Precision::fast())?;
/// let c = &plan.evaluate(&p).coefficients[0];
/// // A and B at μ = 1, f = 0.483135, b = 1 (FAST-PT: A = 1020.3, B = 193.32 at k = 0.0998).
/// let (a, _) = c.a_polynomial(0.483135, 1.0);
/// let (b, _) = c.b_polynomial(0.483135, 1.0);
/// assert!((a.iter().sum::<f64>() - 1030.0).abs() < 20.0);
/// assert!((b.iter().sum::<f64>() - 195.0).abs() < 5.0);
/// # Ok::<(), pt_spectra::error::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct TnsPlan {
    k: Vec<f64>,
    precision: Precision,
    fine: Rule,
    coarse: Rule,
}

/// Bytes per output k of the plan at the default node density (measured 0.9 MB, rounded up).
const BYTES_PER_K: f64 = 1.0e6;

impl TnsPlan {
    /// The estimated memory of a plan on `nk` wavenumbers with `precision` \[bytes\] (its rules at
    /// `BYTES_PER_K` per k, scaled with the node density), which the plans that hold it
    /// ([`crate::real::RealPlan`], [`crate::rsd::RsdPlan`]) check against the limit before they allocate.
    pub fn memory_estimate(nk: usize, precision: &Precision) -> f64 {
        BYTES_PER_K * crate::memory::node_density(precision) * nk as f64
    }

    /// The plan for wavenumbers `k` [h/Mpc], with the P22 settings of `precision`.
    ///
    /// # Errors
    /// As [`crate::loops::OneLoopPlan::new`].
    pub fn new(k: &[f64], precision: &Precision) -> Result<Self> {
        super::one_loop::validate_grid(k, precision)?;
        let lattice = Lattice::new(precision.q_min, precision.q_max, precision.lattice_step);
        let rule = |lattice: Lattice, drop: usize| {
            let layout = Layout::new(precision, drop);
            Rule {
                nodes: PairNodes::new(k, &lattice, &layout, &node_weights),
                lattice,
            }
        };
        Ok(Self {
            k: k.to_vec(),
            precision: precision.clone(),
            coarse: rule(lattice.coarse(), super::one_loop::COARSE_ORDER_DROP),
            fine: rule(lattice, 0),
        })
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.k
    }

    /// The settings the plan was built with.
    pub fn precision(&self) -> &Precision {
        &self.precision
    }

    /// The fine rule and the half-resolution rule of the error estimates (the basis tensors of
    /// [`super::basis::TnsBasis`] are made from them).
    pub(crate) fn rules(&self) -> (&Rule, &Rule) {
        (&self.fine, &self.coarse)
    }

    /// The coefficients for `spectrum`, one k after the other on the calling thread.
    pub fn evaluate(&self, spectrum: &LinearSpectrum) -> TnsTerms {
        let samples = self.samples(spectrum);
        let coefficients = (0..self.k.len()).map(|i| self.at(i, &samples)).collect();
        self.assemble(spectrum, coefficients)
    }

    /// As [`evaluate`](Self::evaluate), with the k values shared out over rayon's pool (bit-identical).
    pub fn par_evaluate(&self, spectrum: &LinearSpectrum) -> TnsTerms {
        let samples = self.samples(spectrum);
        let coefficients = (0..self.k.len())
            .into_par_iter()
            .with_min_len(4)
            .map(|i| self.at(i, &samples))
            .collect();
        self.assemble(spectrum, coefficients)
    }

    /// The spectrum on the fine lattice and on every other point of it.
    fn samples(&self, spectrum: &LinearSpectrum) -> [Vec<f64>; 2] {
        let fine = self.fine.lattice.sample(spectrum);
        let coarse = fine.iter().step_by(2).copied().collect();
        [fine, coarse]
    }

    /// The coefficients at k index i, with the change from the half-resolution rule as the error.
    fn at(&self, i: usize, [fine, coarse]: &[Vec<f64>; 2]) -> TnsCoefficients {
        let floor = self.precision.p22_error_floor;
        let u = self.fine.lattice.position(self.k[i]);
        let p_k = self.fine.lattice.interpolate(fine, u);
        let p_k_coarse = self.coarse.lattice.interpolate(coarse, 0.5 * u);
        let a = self.fine.coefficients(i, fine, p_k);
        let b = self.coarse.coefficients(i, coarse, p_k_coarse);
        let e = |t: usize| Estimate::new(a[t], (a[t] - b[t]).abs() + floor * a[t].abs());
        TnsCoefficients {
            a: std::array::from_fn(e),
            b: std::array::from_fn(|t| e(A_LEN + t)),
        }
    }

    fn assemble(&self, spectrum: &LinearSpectrum, coefficients: Vec<TnsCoefficients>) -> TnsTerms {
        TnsTerms {
            k: self.k.clone(),
            p_lin: self.k.iter().map(|&k| spectrum.eval(k)).collect(),
            coefficients,
            basis_residual: None,
            basis_soft: None,
        }
    }

    /// Number of quadrature nodes (fine rule, all k), a measure of the cost of an evaluation.
    pub fn nodes(&self) -> usize {
        self.fine.nodes.len()
    }
}

/// The TNS coefficients of `spectrum` at `k` [h/Mpc]: builds a [`TnsPlan`] and evaluates it (in parallel).
///
/// # Errors
/// As [`TnsPlan::new`].
pub fn tns(spectrum: &LinearSpectrum, k: &[f64], precision: &Precision) -> Result<TnsTerms> {
    Ok(TnsPlan::new(k, precision)?.par_evaluate(spectrum))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_indices_are_dense() {
        let a: Vec<usize> = (1..=3)
            .flat_map(|m| (1..=m).map(move |n| a_index(n, m)))
            .collect();
        assert_eq!(a, (0..A_LEN).collect::<Vec<_>>());
        let b: Vec<usize> = (2..=4)
            .flat_map(|m| (1..=m).map(move |n| b_index(n, m)))
            .collect();
        assert_eq!(b, (0..B_LEN).collect::<Vec<_>>());
    }

    #[test]
    fn azimuthal_averages_match_quadrature() {
        // ⟨(aμ + bw)^4 (cμ + dw)^2⟩ at several μ against a brute-force average over φ.
        let f = Form::linear(0.3, -0.8)
            .mul(&Form::linear(0.3, -0.8))
            .mul(&Form::linear(0.3, -0.8))
            .mul(&Form::linear(0.3, -0.8))
            .mul(&Form::linear(1.1, 0.4))
            .mul(&Form::linear(1.1, 0.4));
        let avg = f.average();
        for mu in [0.0, 0.3, 0.77, 1.0] {
            let nu = (1.0f64 - mu * mu).sqrt();
            let n = 64;
            let brute: f64 = (0..n)
                .map(|i| {
                    let w = nu * (2.0 * PI * i as f64 / n as f64).cos();
                    (0.3 * mu - 0.8 * w).powi(4) * (1.1 * mu + 0.4 * w).powi(2)
                })
                .sum::<f64>()
                / n as f64;
            let poly: f64 = avg
                .iter()
                .enumerate()
                .map(|(j, c)| c * mu.powi(2 * j as i32))
                .sum();
            assert!((poly - brute).abs() < 1e-14, "μ = {mu}: {poly} vs {brute}");
        }
    }
}
