//! The Gaussian covariance of window-free multipoles with shot noise (module docs of
//! [`super`]) and the Fisher sums over shells.

use super::SurveyBin;
use crate::error::{Error, Result};
use crate::integrate::legendre_nodes;
use crate::survey::legendre;
use std::f64::consts::PI;

/// Gauss–Legendre nodes of the μ integral on [0, 1] (the integrand is even, a polynomial of degree
/// ≤ 24 in μ for P(k, μ) of ℓ ≤ 8 and ℓ, ℓ' ≤ 4: exact).
const MU_NODES: usize = 24;

/// C_ℓℓ'(k) of one shell (`ells` × `ells`, row-major): N_k modes, P(k, μ) = Σ_ℓ `p_ell`[ℓ/2] L_ℓ(μ)
/// (ℓ = 0 … 8, noise-free) and number density `n_bar`.
pub fn gaussian_covariance(ells: &[usize], p_ell: &[f64; 5], n_bar: f64, modes: f64) -> Vec<f64> {
    let (x, w) = legendre_nodes(MU_NODES);
    let n = ells.len();
    let mut c = vec![0.0; n * n];
    for (&x, &w) in x.iter().zip(&w) {
        // μ ∈ [0, 1]: ∫_{−1}^{1} = 2 ∫_0^1 for the even integrand; dμ = dx/2
        let mu = 0.5 * (1.0 + x);
        let p: f64 = (0..5).map(|j| p_ell[j] * legendre(2 * j, mu)).sum::<f64>() + 1.0 / n_bar;
        for a in 0..n {
            for b in 0..n {
                c[a * n + b] += w * legendre(ells[a], mu) * legendre(ells[b], mu) * p * p;
            }
        }
    }
    for a in 0..n {
        for b in 0..n {
            c[a * n + b] *= ((2 * ells[a] + 1) * (2 * ells[b] + 1)) as f64 / modes;
        }
    }
    c
}

/// Per shell, C_ℓℓ' of `bin` from the fiducial data vector `all` (ℓ = 0 … 8, ℓ-major over the
/// shells).
pub(super) fn shell_covariances(
    all: &[f64],
    shells: &[(f64, f64, f64)],
    bin: &SurveyBin,
) -> Result<Vec<Vec<f64>>> {
    let n_k = shells.len();
    shells
        .iter()
        .enumerate()
        .map(|(j, &(_, lo, hi))| {
            let modes =
                bin.volume * 4.0 * PI / 3.0 * (hi.powi(3) - lo.powi(3)) / (2.0 * PI).powi(3);
            let p: [f64; 5] = std::array::from_fn(|l| all[l * n_k + j]);
            if !p[0].is_finite() || p[0] <= 0.0 {
                return Err(Error::InvalidChoice {
                    what: format!(
                        "the fiducial monopole at k = {} h/Mpc (z = {})",
                        shells[j].0, bin.z
                    ),
                    reason: format!("P0 = {} is not positive: no Gaussian covariance", p[0]),
                });
            }
            Ok(gaussian_covariance(&bin.ells, &p, bin.n_bar, modes))
        })
        .collect()
}

/// Adds Σ_k J_kᵀ C_k⁻¹ J_k to `fisher` at the rows and columns `index` (one per row of `jacobian`,
/// each a derivative of the data vector: ℓ-major over `n_k` shells, `n_ell` multipoles).
pub(super) fn add_fisher(
    fisher: &mut [Vec<f64>],
    index: &[usize],
    jacobian: &[Vec<f64>],
    covariances: &[Vec<f64>],
    n_ell: usize,
    n_k: usize,
) {
    for (j, c) in covariances.iter().enumerate() {
        let rows: Vec<Vec<f64>> = (0..n_ell)
            .map(|a| c[a * n_ell..(a + 1) * n_ell].to_vec())
            .collect();
        let inverse = super::invert_spd(&rows).expect("a Gaussian covariance is positive definite");
        // the derivatives at this shell, per parameter
        let d: Vec<Vec<f64>> = jacobian
            .iter()
            .map(|row| (0..n_ell).map(|a| row[a * n_k + j]).collect())
            .collect();
        for (p, dp) in d.iter().enumerate() {
            for (q, dq) in d.iter().enumerate() {
                let mut s = 0.0;
                for a in 0..n_ell {
                    for b in 0..n_ell {
                        s += dp[a] * inverse[a][b] * dq[b];
                    }
                }
                fisher[index[p]][index[q]] += s;
            }
        }
    }
}

/// The Gaussian variances of the entries of `blocks` (in the data vector's order, after the power
/// spectrum), in `bin`, with the monopole `p0` at the power spectrum's shell centres (the measured
/// power P + 1/n̄ at a side k is that of its shell).
pub(super) fn block_variances(
    blocks: &[Box<dyn crate::statistic::Block>],
    p0: &[f64],
    bin: &SurveyBin,
) -> Result<Vec<f64>> {
    let power = |k: f64| {
        let i = ((k - bin.k_min) / bin.dk - 0.5).round().max(0.0) as usize;
        p0[i.min(p0.len() - 1)] + 1.0 / bin.n_bar
    };
    let survey = crate::statistic::Survey {
        volume: bin.volume,
        dk: bin.dk,
        power: &power,
    };
    let mut out = Vec::new();
    for b in blocks {
        out.extend(b.gaussian_variances(&survey)?);
    }
    Ok(out)
}

/// Adds Σ_t ∂B_t/∂θ_p ∂B_t/∂θ_q / ΔB_t² to `fisher` at `index` (the blocks' rows B of each
/// `jacobian` row follow its first `start` power-spectrum rows; no cross-covariance with P or
/// between entries, Gaussian).
pub(super) fn add_block_fisher(
    fisher: &mut [Vec<f64>],
    index: &[usize],
    jacobian: &[Vec<f64>],
    variance: &[f64],
    start: usize,
) {
    for (p, dp) in jacobian.iter().enumerate() {
        for (q, dq) in jacobian.iter().enumerate() {
            let s: f64 = variance
                .iter()
                .enumerate()
                .map(|(t, v)| dp[start + t] * dq[start + t] / v)
                .sum();
            fisher[index[p]][index[q]] += s;
        }
    }
}
