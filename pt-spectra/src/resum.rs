//! Renormalised-perturbation-theory (RPT) propagators and the resummed spectra built from them.
//!
//! Gil-Marín et al. (2012, arXiv:1209.3771), eq. RPT: P_XY = [P_lin + P22_XY + …] N_X(k) N_Y(k), truncated
//! here at one loop. The propagators (the paper's N_i, Crocce & Scoccimarro 2006, astro-ph/0509418):
//! * N0 = exp(−k²σ_v²/2), the same for δ and θ;
//! * N1 = exp(P13/P_lin), with P13 = P13_δδ for δ and P13_θθ for θ (paper normalisation, the 1-loop
//!   correction being P22 + 2P13), so that N1² = 1 + 2P13/P_lin + … reproduces 1-loop SPT.
//!
//! δθ uses N_δ N_θ. Errors are propagated linearly from the loop terms' estimates:
//! δN0 = N0 k² δσ_v²/2, δN1 = N1 δP13/P_lin, and δ(A·M) = |M| δA + |A| δM.

use crate::loops::{Estimate, OneLoopTerms, Pair};

/// Which 1-loop propagator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Propagator {
    /// N0 = exp(−k²σ_v²/2).
    N0,
    /// N1 = exp(P13/P_lin).
    N1,
}

/// N0(k) = exp(−k²σ_v²/2) with its error, k in h/Mpc, σ_v² in (Mpc/h)².
///
/// ```
/// use pt_spectra::{loops::Estimate, resum::n0};
/// let n = n0(0.1, Estimate::new(36.9, 1e-6));
/// assert!((n.value - (-0.5f64 * 0.01 * 36.9).exp()).abs() < 1e-15);
/// ```
pub fn n0(k: f64, sigma_v2: Estimate) -> Estimate {
    let half = 0.5 * k * k;
    let value = (-half * sigma_v2.value).exp();
    Estimate::new(value, value * half * sigma_v2.error)
}

/// N1 = exp(P13/P_lin) with its error (P13 in the paper's normalisation, (Mpc/h)^3).
///
/// ```
/// use pt_spectra::{loops::Estimate, resum::n1};
/// let n = n1(Estimate::new(-50.0, 0.01), 5000.0);
/// assert!((n.value - (-0.01f64).exp()).abs() < 1e-15);
/// ```
pub fn n1(p13: Estimate, p_lin: f64) -> Estimate {
    let value = (p13.value / p_lin).exp();
    Estimate::new(value, value * p13.error / p_lin)
}

/// The propagators (N_δ, N_θ) at every k of `terms`.
pub fn propagators(kind: Propagator, terms: &OneLoopTerms) -> (Vec<Estimate>, Vec<Estimate>) {
    match kind {
        Propagator::N0 => {
            let n: Vec<Estimate> = terms.k.iter().map(|&k| n0(k, terms.sigma_v2)).collect();
            (n.clone(), n)
        }
        Propagator::N1 => {
            let of = |p13: &[Estimate]| -> Vec<Estimate> {
                p13.iter()
                    .zip(&terms.p_lin)
                    .map(|(&p, &lin)| n1(p, lin))
                    .collect()
            };
            (of(&terms.dd.p13), of(&terms.tt.p13))
        }
    }
}

/// Product of two estimates, errors propagated linearly.
pub fn product(a: Estimate, b: Estimate) -> Estimate {
    Estimate::new(
        a.value * b.value,
        a.value.abs() * b.error + b.value.abs() * a.error,
    )
}

/// The damping factors N_X N_Y of δδ, δθ and θθ at k index `i`, from (N_δ, N_θ).
pub fn factors(n: &(Vec<Estimate>, Vec<Estimate>), i: usize) -> [Estimate; 3] {
    let (d, t) = (n.0[i], n.1[i]);
    [product(d, d), product(d, t), product(t, t)]
}

/// The 1-loop RPT spectrum of `pair` at k index `i`: [P_lin + P22] N_X N_Y.
pub fn one_loop_rpt(
    terms: &OneLoopTerms,
    n: &(Vec<Estimate>, Vec<Estimate>),
    pair: Pair,
    i: usize,
) -> Estimate {
    let p22 = terms.pair(pair).p22[i];
    let base = Estimate::new(terms.p_lin[i] + p22.value, p22.error);
    let index = Pair::ALL.iter().position(|&p| p == pair).unwrap_or(0);
    product(base, factors(n, i)[index])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_propagate_linearly() {
        let a = Estimate::new(2.0, 0.1);
        let b = Estimate::new(-3.0, 0.2);
        let p = product(a, b);
        assert_eq!(p.value, -6.0);
        assert!((p.error - (2.0 * 0.2 + 3.0 * 0.1)).abs() < 1e-15);
        let n = n1(Estimate::new(-10.0, 1.0), 100.0);
        assert!((n.error - n.value / 100.0).abs() < 1e-15);
    }
}
