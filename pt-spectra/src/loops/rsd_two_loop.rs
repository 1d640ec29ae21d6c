//! The 2-loop SPT correction of the matter power spectrum in redshift space, P^(2)_s(k, μ; f), by
//! randomised quasi-Monte Carlo over both loop momenta and the azimuth of the line of sight.
//!
//! With the redshift-space kernels Z_n (module `zn`; Scoccimarro, Couchman & Frieman 1999) in place of F_n,
//! the 2-loop terms are those of real space ([`super::two_loop`]; Taule & Garny 2023 compute the same):
//!
//! ```text
//! P^(2)_s = 2P15 + 2P24 + P33red + P33irr,
//! 2P15   = 30 Z₁(k)P(k) ∫∫ Z₅(k, q₁, −q₁, q₂, −q₂) P₁P₂,
//! P33red = 9 P(k) ∫Z₃(k, q₁, −q₁)P₁ ∫Z₃(k, q₂, −q₂)P₂,
//! 2P24   = 24 ∫∫ Z₂(q₁, k − q₁) Z₄(q₁, k − q₁, q₂, −q₂) P(q₁)P(|k − q₁|)P(q₂),
//! P33irr = 6 ∫∫ Z₃(q₁, q₂, q₃)² P(q₁)P(q₂)P(q₃),  q₃ = k − q₁ − q₂,
//! ```
//!
//! ∫ ≡ ∫d³q/(2π)³, Z₁(k) = 1 + fμ². The sum is integrated as the two infrared-safe parts of the
//! real-space correction, on the same 6-D Sobol points (module `integrand`): the propagator part
//! 2P15 − P33red on a broad radial map (its UV tail reaches q ≫ k), and the mode-coupling part
//! 2P24 + P33irr + 2P33red on the real-space mode-coupling map ([`super::two_loop`]): P24 restricted
//! to |k − q₁| > q₁ and P33irr to q₃ > q₁, q₂ by smooth partitions of unity, symmetrised in q₁ ↔ q₂
//! and averaged over the four images q_i → ±q_i. In each part the infrared pieces (∝ [(k + fμk n̂)·q]²/q⁴
//! as q → 0, the redshift-space displacement) cancel at every point. The sixth dimension is the
//! azimuth φ_n of the line of sight n̂ about k̂, taken with its opposite φ_n + π; its cosine μ runs
//! over seven fixed nodes (Chebyshev points in μ² ∈ [0, 1]) at every point.
//!
//! P^(2)_s is a polynomial of degree 6 in f, and its f^m part one of degree ≤ m in μ² (Z_n's f^m part
//! is homogeneous of degree 2m in n̂); with the two opposite azimuths every point's integrand is
//! already such a polynomial, so the seven nodes' values, as polynomials in f, hold it exactly, and
//! the 28 coefficients of f^m μ^{2j}, j ≤ m, are kept. P(k, μ) is the Lagrange
//! interpolant of the nodes in μ², the multipoles its exact Legendre moments (any even ℓ ≤ 12).
//!
//! At f = 0 the integrand is the real-space one (Z_n = F_n); the large-scale limit is
//! P^(2)_s/P_lin → 0 (∝ k², from its UV-sensitive k²P(k) pieces), leaving Kaiser. The value is the
//! mean over R independent random shifts of the Sobol sequence and its error their standard error,
//! for every linear functional (a multipole at one f) computed replica by replica, so correlations
//! between the nodes, the powers of f and spectra integrated together ([`rsd_two_loop_of`]) are
//! carried.

mod integrand;
mod zn;
#[cfg(test)]
pub(crate) use zn::redshift_weights;
pub(crate) use zn::{at as kernel_at, redshift_polynomial};

pub(crate) use integrand::{rsd_min_points, rsd_points_at, Sampling};

use super::mode_coupling::Sampled;
use super::two_loop::integral_scale;
use super::{lattice::Lattice, Estimate, TwoLoopSettings};
use crate::error::{Error, Result};
use crate::integrate::legendre_nodes;
use crate::linear::LinearSpectrum;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Nodes in μ² (and the degree + 1 of the polynomial in μ²).
pub const MU_NODES: usize = 7;
/// Powers f⁰ … f⁶ of the growth rate.
pub const F_POWERS: usize = 7;
/// Largest multipole order of [`RsdTwoLoopTerms::multipoles`]: P^(2)_s has no higher moment.
pub const MAX_TWO_LOOP_ELL: usize = 12;

/// The integrals of one replica at one k: `[node][power of f]`.
pub(crate) type NodeIntegrals = [[f64; F_POWERS]; MU_NODES];

/// μ² at the nodes: Chebyshev points of [0, 1] (the interpolation in μ² is then well conditioned).
pub fn mu2_nodes() -> [f64; MU_NODES] {
    std::array::from_fn(|j| 0.5 * (1.0 - (PI * (j as f64 + 0.5) / MU_NODES as f64).cos()))
}

/// The 2-loop redshift-space correction of one linear spectrum on a k grid.
#[derive(Debug, Clone, PartialEq)]
pub struct RsdTwoLoopTerms {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// Sobol points per random shift at each k.
    pub points: Vec<usize>,
    /// The replicas' integrals at each k.
    replicas: Vec<Vec<NodeIntegrals>>,
    /// Relative error added for the projection on a basis (0 for the direct integral): ε|value| is
    /// added to the error of every functional ([`RsdTwoLoopBasis`](crate::loops::basis::RsdTwoLoopBasis)).
    pub projection_error: f64,
    /// Per k: a bound on the change of each coefficient ([`to_coefficients`]) by the low-rank form
    /// of basis tensors (empty for the direct integral), added to the error of every functional.
    truncation: Vec<[f64; COEFFICIENTS]>,
}

/// The node weights w_j for which Σ_j w_j P(μ_j²) = ∫₀¹ g(μ) P(μ²) dμ for every polynomial P of
/// degree 6 in μ², by a 32-point Gauss–Legendre rule (exact for polynomial g of degree ≤ 50; g smooth
/// otherwise, e.g. a damping).
pub fn node_weights(g: impl Fn(f64) -> f64) -> [f64; MU_NODES] {
    node_weights_on(&NodeRule::new(), g)
}

/// The 32-point Gauss–Legendre rule of [`node_weights`], made once for many calls
/// ([`node_weights_on`]: the same weights): its μ on [0, 1] and, per node j, the weights times the
/// node's Lagrange polynomial in μ², so that a call evaluates g 32 times.
#[derive(Debug, Clone)]
pub struct NodeRule {
    mu: Vec<f64>,
    weights: [Vec<f64>; MU_NODES],
}

impl NodeRule {
    /// The rule.
    pub fn new() -> Self {
        let (x, w) = legendre_nodes(32);
        let nodes = mu2_nodes();
        let mu: Vec<f64> = x.iter().map(|&x| 0.5 * (x + 1.0)).collect();
        let weights = std::array::from_fn(|j| {
            mu.iter()
                .zip(&w)
                .map(|(&mu, &w)| 0.5 * w * lagrange(&nodes, j, mu * mu))
                .collect()
        });
        Self { mu, weights }
    }
}

impl Default for NodeRule {
    fn default() -> Self {
        Self::new()
    }
}

/// [`node_weights`] on a rule made before.
pub fn node_weights_on(rule: &NodeRule, g: impl Fn(f64) -> f64) -> [f64; MU_NODES] {
    let g: Vec<f64> = rule.mu.iter().map(|&mu| g(mu)).collect();
    std::array::from_fn(|j| rule.weights[j].iter().zip(&g).map(|(w, g)| w * g).sum())
}

/// The mean and standard error over the random shifts of Σ_t Σ_j w_tj P_t^(2)(k_i, μ_j; f) for terms
/// P_t of spectra integrated together ([`rsd_two_loop_of`]: the same points and shifts), with node
/// weights w_t ([`node_weights`]), so that correlated errors cancel as they should.
///
/// # Panics
/// If the terms were not integrated together (different shifts or k grids).
pub fn combined(terms: &[(&RsdTwoLoopTerms, [f64; MU_NODES])], i: usize, f: f64) -> Estimate {
    let powers: [f64; F_POWERS] = std::array::from_fn(|m| f.powi(m as i32));
    let replicas = terms[0].0.replicas[i].len();
    assert!(
        terms
            .iter()
            .all(|(t, _)| t.replicas[i].len() == replicas && t.k == terms[0].0.k),
        "terms integrated together"
    );
    let values: Vec<f64> = (0..replicas)
        .map(|r| {
            terms
                .iter()
                .map(|(t, w)| replica_value(&t.replicas[i][r], w, &powers))
                .sum()
        })
        .collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    // the projection error of each term: ε times the size of its own functional
    let projection: f64 = terms
        .iter()
        .filter(|(t, _)| t.projection_error > 0.0)
        .map(|(t, w)| t.projection_error * combined_value(t, w, i, &powers).abs())
        .sum();
    let truncation: f64 = terms
        .iter()
        .filter_map(|(t, w)| Some(truncation_bound(t.truncation.get(i)?, w, &powers)))
        .sum();
    Estimate::new(mean, (var / n).sqrt() + projection + truncation)
}

/// The largest change of Σ_j w_j Σ_m f^m c_m(μ_j²) for coefficients c_{m,l} (of f^m μ^{2l}) each
/// changed by at most `bound`: Σ_{m,l} f^m |Σ_j w_j μ_j^{2l}| bound_{m,l}.
fn truncation_bound(
    bound: &[f64; COEFFICIENTS],
    weights: &[f64; MU_NODES],
    powers: &[f64; F_POWERS],
) -> f64 {
    let x = mu2_nodes();
    let moment = |l: usize| -> f64 {
        (x.iter().zip(weights))
            .map(|(x, w)| w * x.powi(l as i32))
            .sum()
    };
    (0..F_POWERS)
        .flat_map(|m| (0..=m).map(move |l| (m, l)))
        .map(|(m, l)| powers[m].abs() * moment(l).abs() * bound[m * (m + 1) / 2 + l])
        .sum()
}

/// Σ_j w_j Σ_m f^m c_jm of one replica's integrals `nodes` at one k.
fn replica_value(
    nodes: &NodeIntegrals,
    weights: &[f64; MU_NODES],
    powers: &[f64; F_POWERS],
) -> f64 {
    nodes
        .iter()
        .zip(weights)
        .map(|(node, w)| w * node.iter().zip(powers).map(|(c, p)| c * p).sum::<f64>())
        .sum()
}

/// The mean over the replicas of one term's functional.
fn combined_value(
    t: &RsdTwoLoopTerms,
    weights: &[f64; MU_NODES],
    i: usize,
    powers: &[f64; F_POWERS],
) -> f64 {
    let r = &t.replicas[i];
    r.iter()
        .map(|rep| replica_value(rep, weights, powers))
        .sum::<f64>()
        / r.len() as f64
}

/// Coefficients kept per node set: f^m μ^{2j} with j ≤ m (Z_n's f^m part is homogeneous of degree 2m
/// in the line of sight, so after the azimuth its degree in μ² is at most m).
pub(crate) const COEFFICIENTS: usize = 28;

/// The coefficients c_{m,j} of f^m μ^{2j}, j ≤ m, at index m(m+1)/2 + j, of the node values (the
/// interpolant's higher powers of μ², zero in expectation, dropped).
pub(crate) fn to_coefficients(nodes: &NodeIntegrals) -> [f64; COEFFICIENTS] {
    let inverse = vandermonde_inverse();
    let mut c = [0.0; COEFFICIENTS];
    for m in 0..F_POWERS {
        for j in 0..=m {
            c[m * (m + 1) / 2 + j] = (0..MU_NODES).map(|n| inverse[j][n] * nodes[n][m]).sum();
        }
    }
    c
}

/// The node values of the coefficients of [`to_coefficients`].
pub(crate) fn from_coefficients(c: &[f64; COEFFICIENTS]) -> NodeIntegrals {
    let x = mu2_nodes();
    std::array::from_fn(|n| {
        std::array::from_fn(|m| {
            (0..=m)
                .map(|j| c[m * (m + 1) / 2 + j] * x[n].powi(j as i32))
                .sum()
        })
    })
}

/// The node values with the powers of μ² above f's dropped.
fn truncated(nodes: &NodeIntegrals) -> NodeIntegrals {
    from_coefficients(&to_coefficients(nodes))
}

impl RsdTwoLoopTerms {
    /// The terms from the replicas' coefficients ([`to_coefficients`]) at each k.
    pub(crate) fn from_coefficients(
        k: &[f64],
        points: Vec<usize>,
        replicas: &[Vec<[f64; COEFFICIENTS]>],
        projection_error: f64,
        truncation: Vec<[f64; COEFFICIENTS]>,
    ) -> Self {
        Self {
            k: k.to_vec(),
            points,
            replicas: replicas
                .iter()
                .map(|r| r.iter().map(from_coefficients).collect())
                .collect(),
            projection_error,
            truncation,
        }
    }

    /// The mean and standard error over the replicas of Σ_j w_j P^(2)(k_i, μ_j; f).
    pub fn functional(&self, i: usize, f: f64, weights: &[f64; MU_NODES]) -> Estimate {
        combined(&[(self, *weights)], i, f)
    }

    /// P^(2)_s(k_i, μ) at growth rate `f` [(Mpc/h)³].
    pub fn at(&self, i: usize, f: f64, mu: f64) -> Estimate {
        let x = mu * mu;
        let nodes = mu2_nodes();
        let weights = std::array::from_fn(|j| lagrange(&nodes, j, x));
        self.functional(i, f, &weights)
    }

    /// The multipoles P^(2)_ℓ(k_i) = (2ℓ+1)∫₀¹ L_ℓ(μ) P^(2)_s dμ at growth rate `f`, for every ℓ of
    /// `ells` (even, ≤ [`MAX_TWO_LOOP_ELL`]; checked by [`check_ells`]).
    pub fn multipoles(&self, i: usize, f: f64, ells: &[usize]) -> Vec<Estimate> {
        ells.iter()
            .map(|&ell| self.functional(i, f, &moment_weights(ell)))
            .collect()
    }

    /// [`multipoles`](Self::multipoles) at every k (by k, then ℓ), with the moment weights of each ℓ
    /// made once.
    pub fn multipoles_at_every_k(&self, f: f64, ells: &[usize]) -> Vec<Vec<Estimate>> {
        let weights: Vec<[f64; MU_NODES]> = ells.iter().map(|&ell| moment_weights(ell)).collect();
        (0..self.k.len())
            .map(|i| weights.iter().map(|w| self.functional(i, f, w)).collect())
            .collect()
    }

    /// The coefficients of μ^{2n}, n = 0..=6, of P^(2)_s(k_i, μ) at growth rate `f`.
    pub fn mu_coefficients(&self, i: usize, f: f64) -> [Estimate; MU_NODES] {
        let inverse = vandermonde_inverse();
        std::array::from_fn(|n| self.functional(i, f, &inverse[n]))
    }
}

/// The j-th Lagrange basis polynomial of `nodes` at x.
fn lagrange(nodes: &[f64; MU_NODES], j: usize, x: f64) -> f64 {
    (0..MU_NODES)
        .filter(|&i| i != j)
        .map(|i| (x - nodes[i]) / (nodes[j] - nodes[i]))
        .product()
}

/// L_ℓ(μ) by the upward recursion.
pub(crate) fn legendre(ell: usize, mu: f64) -> f64 {
    let (mut prev, mut cur) = (1.0, mu);
    if ell == 0 {
        return 1.0;
    }
    for j in 1..ell {
        let next = ((2 * j + 1) as f64 * mu * cur - j as f64 * prev) / (j + 1) as f64;
        prev = cur;
        cur = next;
    }
    cur
}

/// w_j = (2ℓ+1)∫₀¹ L_ℓ(μ) ℓ_j(μ²) dμ ([`node_weights`]: exact, the integrand is of degree 12 + ℓ).
fn moment_weights(ell: usize) -> [f64; MU_NODES] {
    node_weights(|mu| (2 * ell + 1) as f64 * legendre(ell, mu))
}

/// Row n gives the coefficient of x^n of the interpolant from the node values: the coefficients of
/// the Lagrange basis polynomials, expanded.
fn vandermonde_inverse() -> [[f64; MU_NODES]; MU_NODES] {
    let nodes = mu2_nodes();
    let mut rows = [[0.0; MU_NODES]; MU_NODES];
    for j in 0..MU_NODES {
        let mut poly = vec![1.0];
        let mut denominator = 1.0;
        for (i, &xi) in nodes.iter().enumerate() {
            if i == j {
                continue;
            }
            denominator *= nodes[j] - xi;
            let mut next = vec![0.0; poly.len() + 1];
            for (p, c) in poly.iter().enumerate() {
                next[p + 1] += c;
                next[p] -= xi * c;
            }
            poly = next;
        }
        for (n, c) in poly.iter().enumerate() {
            rows[n][j] = c / denominator;
        }
    }
    rows
}

/// Refuses multipole orders that are odd or above [`MAX_TWO_LOOP_ELL`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming the first bad ℓ.
pub fn check_ells(ells: &[usize]) -> Result<()> {
    match ells.iter().find(|&&l| l % 2 == 1 || l > MAX_TWO_LOOP_ELL) {
        Some(&bad) => Err(Error::InvalidParameter {
            name: "multipole ell of the 2-loop redshift-space spectrum",
            value: bad as f64,
            reason: "must be even and at most 12",
        }),
        None => Ok(()),
    }
}

/// The 2-loop redshift-space correction of `spectrum` at `k` [h/Mpc], over q ∈ `q_range` (P̃ on a
/// lattice of step `lattice_step` in ln q), with `settings.points` Sobol points per shift at
/// k = 0.16 h/Mpc scaled as the real-space ones ([`TwoLoopSettings::points`]; no refinement),
/// `settings.replicas` shifts; `progress(done, total)` counts the points.
///
/// # Errors
/// [`Error::InvalidParameter`] for fewer than 2 replicas or a k that is not positive and finite.
pub fn rsd_two_loop(
    k: &[f64],
    spectrum: &LinearSpectrum,
    q_range: (f64, f64),
    lattice_step: f64,
    settings: &TwoLoopSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<RsdTwoLoopTerms> {
    let mut terms = rsd_two_loop_of(k, &[spectrum], q_range, lattice_step, settings, progress)?;
    Ok(terms.remove(0))
}

/// [`rsd_two_loop`] of several spectra on the same points: the kernels, the costly part, are
/// evaluated once per point for all of them, and their Monte Carlo errors are correlated, so a
/// difference such as P^(2)\[P\] − P^(2)\[P_nw\] (through [`combined`]) carries a much smaller error
/// than either.
///
/// # Errors
/// As [`rsd_two_loop`]; [`Error::InvalidParameter`] for no spectra.
pub fn rsd_two_loop_of(
    k: &[f64],
    spectra: &[&LinearSpectrum],
    q_range: (f64, f64),
    lattice_step: f64,
    settings: &TwoLoopSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<RsdTwoLoopTerms>> {
    if settings.replicas < 2 {
        return Err(Error::InvalidParameter {
            name: "two_loop_replicas",
            value: settings.replicas as f64,
            reason: "at least 2 random shifts are needed for an error estimate",
        });
    }
    if spectra.is_empty() {
        return Err(Error::InvalidParameter {
            name: "number of spectra of the 2-loop redshift-space terms",
            value: 0.0,
            reason: "must be at least 1",
        });
    }
    if let Some(&bad) = k.iter().find(|&&k| !(k > 0.0 && k.is_finite())) {
        return Err(Error::InvalidParameter {
            name: "k of the 2-loop redshift-space spectrum",
            value: bad,
            reason: "must be positive and finite",
        });
    }
    let lattice = Lattice::new(q_range.0, q_range.1, lattice_step);
    let samples: Vec<Vec<f64>> = spectra.iter().map(|s| lattice.sample(s)).collect();
    let sampled: Vec<Sampled> = samples
        .iter()
        .map(|samples| Sampled {
            lattice: &lattice,
            samples,
        })
        .collect();
    let sampling = Sampling::new(k, q_range, settings);
    let counts = &sampling.counts;
    let replicas = sampling.shifts.len();
    let total: usize = counts.iter().map(|n| n * replicas).sum();
    let done = AtomicUsize::new(0);
    // per job (k, shift): the integrals of every spectrum
    let integrals: Vec<Vec<NodeIntegrals>> = (0..k.len() * replicas)
        .into_par_iter()
        .map(|job| {
            let (i, shift) = (job / replicas, &sampling.shifts[job % replicas]);
            let samplers = sampling.samplers(k[i]);
            let mut acc = vec![[[0.0; F_POWERS]; MU_NODES]; spectra.len()];
            for unit in &sampling.points[..counts[i]] {
                for legs in sampling.legs(k[i], unit, shift, &samplers) {
                    for (s, a) in sampled.iter().zip(acc.iter_mut()) {
                        legs.add_to(s, a);
                    }
                }
            }
            let scale = integral_scale(counts[i]);
            progress(
                done.fetch_add(counts[i], Ordering::Relaxed) + counts[i],
                total,
            );
            // the powers of μ² above f's, zero in expectation, dropped (as the basis tensors do)
            acc.into_iter()
                .map(|a| truncated(&a.map(|row| row.map(|v| v * scale))))
                .collect()
        })
        .collect();
    Ok((0..spectra.len())
        .map(|s| RsdTwoLoopTerms {
            k: k.to_vec(),
            points: counts.clone(),
            projection_error: 0.0,
            truncation: Vec::new(),
            replicas: integrals
                .chunks(replicas)
                .map(|jobs| jobs.iter().map(|per| per[s]).collect())
                .collect(),
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_functionals_are_exact_on_polynomials_in_mu_squared() {
        let nodes = mu2_nodes();
        // p(μ) = Σ c_n μ^{2n}, degree 6 in μ²
        let c = [1.0, -2.0, 0.5, 3.0, -1.0, 0.25, 2.0];
        let p = |x: f64| c.iter().rev().fold(0.0, |a, cn| a * x + cn);
        let values: Vec<f64> = nodes.iter().map(|&x| p(x)).collect();
        let inverse = vandermonde_inverse();
        for (n, row) in inverse.iter().enumerate() {
            let got: f64 = row.iter().zip(&values).map(|(w, v)| w * v).sum();
            assert!((got - c[n]).abs() < 1e-10, "μ^{}: {got}", 2 * n);
        }
        // (2ℓ+1)∫₀¹ μ^{2n} L_ℓ dμ in closed form: ℓ = 0: 1/(2n+1); ℓ = 2: 5(3/(2n+3) − 1/(2n+1))/2
        for ell in [0usize, 2, 4, 12] {
            let w = moment_weights(ell);
            let got: f64 = w.iter().zip(&values).map(|(w, v)| w * v).sum();
            let (x, gw) = legendre_nodes(40);
            let want: f64 = x
                .iter()
                .zip(&gw)
                .map(|(&x, &g)| {
                    let mu = 0.5 * (x + 1.0);
                    (2 * ell + 1) as f64 * 0.5 * g * legendre(ell, mu) * p(mu * mu)
                })
                .sum();
            assert!((got - want).abs() < 1e-12, "ℓ = {ell}: {got} vs {want}");
        }
        let w0 = moment_weights(0);
        let mono: f64 = w0.iter().zip(&values).map(|(w, v)| w * v).sum();
        let exact: f64 = c
            .iter()
            .enumerate()
            .map(|(n, cn)| cn / (2 * n + 1) as f64)
            .sum();
        assert!((mono - exact).abs() < 1e-12);
        assert!(check_ells(&[0, 2, 12]).is_ok());
        assert!(check_ells(&[3]).is_err() && check_ells(&[14]).is_err());
    }
}
