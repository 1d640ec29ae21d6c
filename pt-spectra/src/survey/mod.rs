//! From a model to a measured data vector: the survey window and the k bins (issue 25, parts 2 and 3).
//!
//! Units: k in h/Mpc, s in Mpc/h, P in (Mpc/h)^3, ξ and Q dimensionless. Multipoles are those of the
//! plane-parallel (global line-of-sight) expansion P(k, μ) = Σ_ℓ P_ℓ(k) L_ℓ(μ), ξ(s, μ) = Σ_ℓ ξ_ℓ(s) L_ℓ(μ),
//! with ξ_ℓ(s) = i^ℓ ∫ k² dk/(2π²) P_ℓ(k) j_ℓ(ks) (the conventions of [`crate::hankel`]).
//!
//! The pipeline a likelihood evaluates per step:
//!
//! ```text
//!   model P_ℓ'(k_t), ℓ' = 0, 2, 4 [, 6, 8]       at the k_t a plan asks for (`k_theory()`)
//!     → window  P̂_ℓ(k) = W[P_ℓ']                [`WindowPlan`] (Q_ℓ(s) multipoles) or [`WindowMatrix`]
//!     → bins    P̂_ℓ(bin) = <P̂_ℓ>_bin             [`BinAverage`] (k² weight) or [`BoxModes`] (box modes)
//!     → data vector
//! ```
//!
//! A windowed, binned evaluation chains the plans backwards: the bins' `k_theory()` are the window plan's
//! output k, and the window plan's `k_theory()` are where the model is evaluated.
//!
//! * Window, configuration space (Wilson, Peacock, Percival & Ross 2017, MNRAS 464, 3121): the measured
//!   ξ̂(s, μ) = ξ(s, μ) Q(s, μ), so ξ̂_ℓ(s) = Σ_{ℓ',ℓ''} (2ℓ+1) (ℓ ℓ' ℓ''; 0 0 0)² ξ_ℓ'(s) Q_ℓ''(s), and
//!   P̂_ℓ(k) = 4π (−i)^ℓ ∫ s² ds ξ̂_ℓ(s) j_ℓ(ks) ([`window`]).
//! * Window, matrix: P̂ = W P with W read from a file ([`WindowMatrix`]).
//! * Bins: the mean over a bin with the mode-count weight k², P̂(bin) = ∫ k² P̂ dk / ∫ k² dk
//!   ([`BinAverage`]), or the mean over the discrete modes k = (2π/L) n of a periodic box of side L,
//!   P̂_ℓ(bin) = (2ℓ+1) ⟨P(k_n, μ_n) L_ℓ(μ_n)⟩_n ([`BoxModes`]).
//!
//! Neglected: wide-angle terms (the window multipoles are those of a single line of sight; the odd
//! multipoles and the (s/d)^n corrections of Beutler et al. 2019 are not modelled), the integral
//! constraint (subtract it from the model if the data need it), and the window's redshift evolution.
//!
//! Normalisation: Q_ℓ(s) are normalised so that Q0(s → 0) = 1, as in the BOSS DR12 files, so that a
//! window that does not cut anything (Q0 = 1, Q_ℓ>0 = 0) leaves P_ℓ unchanged. A file whose Q0 at its
//! smallest s differs from 1 is used as it is, i.e. the model is multiplied by Q0(0) at high k:
//! [`WindowMultipoles::normalisation`] returns Q0(0) and [`WindowMultipoles::normalisation_warning`] a
//! message when it is off by more than 1e-3; [`WindowMultipoles::normalised`] divides it out.
//!
//! ```
//! use pt_spectra::linear::LinearSpectrum;
//! use pt_spectra::survey::{BinAverage, Mixing, WindowMultipoles, WindowPlan};
//! // A uniform sphere of radius R = 300 Mpc/h: Q0(s) = 1 − 3s/4R + s³/16R³ for s < 2R.
//! let r = 300.0;
//! let s: Vec<f64> = (0..128).map(|i| 0.01 * (2.0 * r / 0.01f64).powf(i as f64 / 127.0)).collect();
//! let q0 = s.iter().map(|&s| 1.0 - 0.75 * s / r + (s / r).powi(3) / 16.0).collect();
//! let window = WindowMultipoles::from_columns(s, vec![0], vec![q0])?;
//! let edges: Vec<f64> = (0..=48).map(|i| 0.005 * i as f64).collect();
//! let bins = BinAverage::new(&edges)?;
//! let plan = WindowPlan::new(&[0, 2], bins.k_theory(), &window, Mixing::Wilson)?;
//! let p_lin = LinearSpectrum::gm2012(0.0)?;
//! let f = 0.5; // Kaiser: P0 = (1 + 2f/3 + f²/5) P, P2 = (4f/3 + 4f²/7) P
//! let model: Vec<Vec<f64>> = [1.0 + 2.0 * f / 3.0 + f * f / 5.0, 4.0 * f / 3.0 + 4.0 * f * f / 7.0]
//!     .iter()
//!     .map(|c| plan.k_theory().iter().map(|&k| c * p_lin.eval(k)).collect())
//!     .collect();
//! let windowed = plan.apply(&model)?;
//! let p0_bins = bins.apply_estimates(&windowed[0])?;
//! assert_eq!(p0_bins.len(), 48);
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

pub mod bins;
pub mod observe;
mod text;
pub mod window;
pub mod xi;

pub use bins::{BinAverage, BoxModes, BoxModesPlan, ModeGroup};
pub use window::{
    mixing_coefficient, Mixing, WindowFormat, WindowMatrix, WindowMultipoles, WindowOptions,
    WindowPlan,
};
pub use xi::XiPlan;

use crate::error::{Error, Result};

/// The largest multipole ℓ of the model, of the window and of the output.
pub const MAX_ELL: usize = 8;

/// The Legendre polynomial L_ℓ(μ), ℓ ≤ 8 (any ℓ by the recurrence).
pub fn legendre(ell: usize, mu: f64) -> f64 {
    let (mut p0, mut p1) = (1.0, mu);
    if ell == 0 {
        return 1.0;
    }
    for n in 1..ell {
        let nf = n as f64;
        let p2 = ((2.0 * nf + 1.0) * mu * p1 - nf * p0) / (nf + 1.0);
        p0 = p1;
        p1 = p2;
    }
    p1
}

/// Checks a list of multipoles: not empty, even, at most [`MAX_ELL`], no repeats.
fn check_ells(what: &str, ells: &[usize]) -> Result<()> {
    let bad = |reason: String| {
        Err(Error::InvalidChoice {
            what: format!("{what} {ells:?}"),
            reason,
        })
    };
    if ells.is_empty() {
        return bad("at least one multipole is needed".into());
    }
    for (i, &l) in ells.iter().enumerate() {
        if l % 2 == 1 || l > MAX_ELL {
            return bad(format!(
                "ℓ = {l}: only the even multipoles 0, 2, 4, 6, 8 are supported \
                 (odd ones are wide-angle terms, neglected)"
            ));
        }
        if ells[..i].contains(&l) {
            return bad(format!("ℓ = {l} is given twice"));
        }
    }
    Ok(())
}

/// Checks that `k` are finite, positive (or zero if `zero_ok`) and strictly increasing.
fn check_increasing(origin: &str, k: &[f64], zero_ok: bool) -> Result<()> {
    if !zero_ok {
        return crate::table::check_k_grid(origin, k, &[]);
    }
    for (i, &v) in k.iter().enumerate() {
        if !(v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0))) {
            return Err(Error::InvalidK {
                origin: origin.into(),
                line: i + 1,
                k: v,
            });
        }
        if i > 0 && v <= k[i - 1] {
            return Err(Error::NonIncreasingK {
                origin: origin.into(),
                line: i + 1,
                k: v,
                previous: k[i - 1],
            });
        }
    }
    Ok(())
}

/// Checks that the model's multipoles are 1 to 5 arrays of `n` finite values.
fn check_model(what: &'static str, p: &[Vec<f64>], n: usize) -> Result<()> {
    if p.is_empty() || p.len() > MAX_ELL / 2 + 1 {
        return Err(Error::InvalidChoice {
            what: what.into(),
            reason: format!(
                "{} multipoles given; give P_0, P_2, … in order, 1 to 5 of them",
                p.len()
            ),
        });
    }
    for (j, values) in p.iter().enumerate() {
        if values.len() != n {
            return Err(Error::LengthMismatch {
                what: "k_theory and the model's multipole values",
                left: n,
                right: values.len(),
            });
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidValue {
                origin: format!("{what}, P_{}", 2 * j),
                line: i + 1,
                name: "P_ell [(Mpc/h)^3]",
                value: values[i],
                reason: "must be finite",
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn legendre_polynomials() {
        let mu: f64 = 0.3;
        assert_eq!(legendre(0, mu), 1.0);
        assert_eq!(legendre(1, mu), mu);
        assert!((legendre(2, mu) - 0.5 * (3.0 * mu * mu - 1.0)).abs() < 1e-15);
        let l4 = (35.0 * mu.powi(4) - 30.0 * mu * mu + 3.0) / 8.0;
        assert!((legendre(4, mu) - l4).abs() < 1e-15);
        assert!((legendre(8, 1.0) - 1.0).abs() < 1e-14);
    }

    #[test]
    fn multipole_lists_are_checked() {
        assert!(check_ells("ells", &[0, 2, 4]).is_ok());
        for bad in [&[][..], &[1], &[0, 0], &[10]] {
            assert!(matches!(
                check_ells("ells", bad),
                Err(Error::InvalidChoice { .. })
            ));
        }
    }
}
