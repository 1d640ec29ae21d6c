//! Bin averages: over k with the mode-count weight ([`BinAverage`]), or over the discrete modes of a
//! periodic box ([`BoxModes`]).
//!
//! # k bins
//!
//! A measurement in the bin [k_a, k_b) averages over the modes in a shell, whose number grows as k² dk,
//! so the model is averaged with that weight:
//!   P̄(bin) = ∫_{k_a}^{k_b} k² P(k) dk / ∫_{k_a}^{k_b} k² dk,   ∫ k² dk = (k_b³ − k_a³)/3.
//! The numerator is an n-point Gauss–Legendre rule in k on each bin (n = 3 by default; exact for
//! polynomials k²P of degree 2n − 1); the error estimate is its difference to the ⌈n/2⌉-point rule, whose
//! nodes are added to [`BinAverage::k_theory`] (for n = 3: 5 nodes per bin). Each rule is normalised by
//! its own Σ w k², so that a constant is averaged exactly for every n. The
//! bin's effective k, ∫ k³ dk / ∫ k² dk = (3/4)(k_b⁴ − k_a⁴)/(k_b³ − k_a³), is [`BinAverage::k_eff`].
//!
//! # Box modes
//!
//! A simulation of side L measures the discrete modes k = (2π/L)(i, j, l) of its periodic box; the
//! multipoles of a bin are the mean over the modes in it, μ = l/|n| along the z axis:
//!   P̂_ℓ(bin) = (2ℓ+1) (1/N_bin) Σ_{modes n in bin} P(k_n, μ_n) L_ℓ(μ_n)
//! ([`BoxModes`], [`BoxModesPlan`]).

mod modes;

pub use modes::{BoxModes, BoxModesPlan, ModeGroup};

use super::check_increasing;
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::integrate::legendre_nodes;

/// The Gauss–Legendre nodes of the bins of a set of k edges, and the k²-weighted bin means (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct BinAverage {
    edges: Vec<f64>,
    nodes: Vec<f64>,
    /// Per bin: (node index, weight · k² / Σ weight · k²) of the n-point and of the ⌈n/2⌉-point rule.
    fine: Vec<Vec<(usize, f64)>>,
    coarse: Vec<Vec<(usize, f64)>>,
}

impl BinAverage {
    /// The bins between consecutive `k_edges` [h/Mpc] (k_0 may be 0), 3-point rules.
    ///
    /// # Errors
    /// As [`with_nodes`](Self::with_nodes).
    pub fn new(k_edges: &[f64]) -> Result<Self> {
        Self::with_nodes(k_edges, 3)
    }

    /// The bins with `n`-point Gauss–Legendre rules (1 ≤ n ≤ 64).
    ///
    /// # Errors
    /// [`Error::TooFewPoints`] for fewer than 2 edges, [`Error::InvalidK`] or [`Error::NonIncreasingK`]
    /// for edges that are not finite, non-negative and increasing, [`Error::InvalidParameter`] for n
    /// outside 1..=64.
    pub fn with_nodes(k_edges: &[f64], n: usize) -> Result<Self> {
        if k_edges.len() < 2 {
            return Err(Error::TooFewPoints {
                origin: "k bin edges".into(),
                found: k_edges.len(),
                min: 2,
            });
        }
        check_increasing("k bin edges", k_edges, true)?;
        if !(1..=64).contains(&n) {
            return Err(Error::InvalidParameter {
                name: "n (Gauss-Legendre nodes per bin)",
                value: n as f64,
                reason: "must be between 1 and 64",
            });
        }
        let rules = [legendre_nodes(n), legendre_nodes(n.div_ceil(2))];
        let mut nodes = Vec::new();
        let (mut fine, mut coarse) = (Vec::new(), Vec::new());
        for e in k_edges.windows(2) {
            let (mid, half) = (0.5 * (e[0] + e[1]), 0.5 * (e[1] - e[0]));
            let first = nodes.len();
            let mut weights = [Vec::new(), Vec::new()];
            for (rule, w) in rules.iter().zip(weights.iter_mut()) {
                for (&x, &wx) in rule.0.iter().zip(&rule.1) {
                    let k = mid + half * x;
                    let i = match nodes[first..].iter().position(|&v| v == k) {
                        Some(i) => first + i,
                        None => {
                            nodes.push(k);
                            nodes.len() - 1
                        }
                    };
                    w.push((i, half * wx * k * k));
                }
                let total: f64 = w.iter().map(|p| p.1).sum();
                w.iter_mut().for_each(|p| p.1 /= total);
            }
            let [f, c] = weights;
            fine.push(f);
            coarse.push(c);
        }
        // Nodes in increasing order, indices remapped.
        let mut order: Vec<usize> = (0..nodes.len()).collect();
        order.sort_by(|&a, &b| nodes[a].total_cmp(&nodes[b]));
        let mut rank = vec![0; nodes.len()];
        order.iter().enumerate().for_each(|(r, &i)| rank[i] = r);
        for w in fine.iter_mut().chain(coarse.iter_mut()) {
            w.iter_mut().for_each(|(i, _)| *i = rank[*i]);
        }
        Ok(Self {
            edges: k_edges.to_vec(),
            nodes: order.iter().map(|&i| nodes[i]).collect(),
            fine,
            coarse,
        })
    }

    /// Where the model must be evaluated: the nodes of all bins, increasing, k in h/Mpc.
    pub fn k_theory(&self) -> &[f64] {
        &self.nodes
    }

    /// The bin edges [h/Mpc].
    pub fn edges(&self) -> &[f64] {
        &self.edges
    }

    /// The number of bins.
    pub fn len(&self) -> usize {
        self.fine.len()
    }

    /// Always false: there is at least one bin.
    pub fn is_empty(&self) -> bool {
        self.fine.is_empty()
    }

    /// The k²-weighted mean k of each bin, (3/4)(k_b⁴ − k_a⁴)/(k_b³ − k_a³) [h/Mpc].
    pub fn k_eff(&self) -> Vec<f64> {
        self.edges
            .windows(2)
            .map(|e| 0.75 * (e[1].powi(4) - e[0].powi(4)) / (e[1].powi(3) - e[0].powi(3)))
            .collect()
    }

    /// The bin means of `values` given at [`k_theory`](Self::k_theory), with the quadrature error estimate.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if `values` is not as long as k_theory, [`Error::InvalidValue`] for a
    /// value that is not finite.
    pub fn apply(&self, values: &[f64]) -> Result<Vec<Estimate>> {
        let exact: Vec<Estimate> = values.iter().map(|&v| Estimate::exact(v)).collect();
        self.apply_estimates(&exact)
    }

    /// [`apply`](Self::apply) for values with errors (e.g. the output of a window plan): the errors are
    /// averaged with the same weights and added to the quadrature error estimate.
    ///
    /// # Errors
    /// As [`apply`](Self::apply).
    pub fn apply_estimates(&self, values: &[Estimate]) -> Result<Vec<Estimate>> {
        if values.len() != self.nodes.len() {
            return Err(Error::LengthMismatch {
                what: "bin nodes (k_theory) and values",
                left: self.nodes.len(),
                right: values.len(),
            });
        }
        if let Some(i) = values.iter().position(|v| !v.value.is_finite()) {
            return Err(Error::InvalidValue {
                origin: "BinAverage::apply".into(),
                line: i + 1,
                name: "value at a bin node",
                value: values[i].value,
                reason: "must be finite",
            });
        }
        Ok(self
            .fine
            .iter()
            .zip(&self.coarse)
            .map(|(fine, coarse)| {
                let mean = |w: &[(usize, f64)]| -> f64 {
                    w.iter().map(|&(i, w)| w * values[i].value).sum()
                };
                let carried: f64 = fine.iter().map(|&(i, w)| w.abs() * values[i].error).sum();
                let (f, c) = (mean(fine), mean(coarse));
                Estimate::new(f, (f - c).abs() + carried)
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn means_of_polynomials_are_exact() {
        let edges = [0.0, 0.01, 0.03, 0.1];
        let bins = BinAverage::new(&edges).unwrap();
        assert_eq!(bins.len(), 3);
        assert_eq!(bins.k_theory().len(), 3 * 5);
        assert!(bins.k_theory().windows(2).all(|w| w[1] > w[0]));
        // Mean of k with weight k²: the effective k; of k³: (3/6)(b⁶ − a⁶)/(b³ − a³).
        let k: Vec<f64> = bins.k_theory().to_vec();
        let mean_k = bins.apply(&k).unwrap();
        for (m, e) in mean_k.iter().zip(bins.k_eff()) {
            assert!((m.value - e).abs() < 1e-15 && m.error < 1e-15, "{m:?} {e}");
        }
        let cubes: Vec<f64> = k.iter().map(|k| k.powi(3)).collect();
        for (m, e) in bins.apply(&cubes).unwrap().iter().zip(edges.windows(2)) {
            let exact = 0.5 * (e[1].powi(6) - e[0].powi(6)) / (e[1].powi(3) - e[0].powi(3));
            assert!(
                (m.value - exact).abs() < 1e-15 * exact.abs().max(1e-6),
                "{m:?} {exact}"
            );
        }
    }

    #[test]
    fn error_estimate_bounds_the_error() {
        let edges = [0.05, 0.1];
        let f = |k: f64| (30.0 * k).sin() / k;
        let exact = {
            // ∫ k sin(30k) dk = sin(30k)/900 − k cos(30k)/30.
            let g = |k: f64| (30.0 * k).sin() / 900.0 - k * (30.0 * k).cos() / 30.0;
            (g(0.1) - g(0.05)) * 3.0 / (0.1f64.powi(3) - 0.05f64.powi(3))
        };
        for n in [2, 3, 5, 8] {
            let bins = BinAverage::with_nodes(&edges, n).unwrap();
            let v: Vec<f64> = bins.k_theory().iter().map(|&k| f(k)).collect();
            let m = bins.apply(&v).unwrap()[0];
            assert!(
                (m.value - exact).abs() <= m.error + 1e-15,
                "n = {n}: {m:?} vs {exact}"
            );
        }
        let carried = BinAverage::with_nodes(&edges, 1).unwrap();
        let m = carried.apply_estimates(&[Estimate::new(2.0, 0.5)]).unwrap()[0];
        assert_eq!(m, Estimate::new(2.0, 0.5));
    }

    #[test]
    fn bad_edges_are_refused() {
        assert!(BinAverage::new(&[0.1]).is_err());
        assert!(BinAverage::new(&[0.1, 0.1]).is_err());
        assert!(BinAverage::new(&[-0.1, 0.1]).is_err());
        assert!(BinAverage::new(&[0.0, f64::NAN]).is_err());
        assert!(BinAverage::with_nodes(&[0.0, 0.1], 0).is_err());
        let bins = BinAverage::new(&[0.0, 0.1]).unwrap();
        assert!(bins.apply(&[1.0; 4]).is_err());
        assert!(bins.apply(&[1.0, 1.0, f64::INFINITY, 1.0, 1.0]).is_err());
    }
}
