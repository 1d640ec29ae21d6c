//! The no-wiggle spectrum of velocileptors' `REPT` (Chen, Vlah, Castorina & White 2021): a
//! Savitzky–Golay filter of P itself, a quartic least-squares fit over a window ln 7 wide in ln k
//! (about one BAO oscillation from k = 0.01 h/Mpc) evaluated at its centre, on a log-uniform grid.
//!
//! The filter is a fixed convolution: for offsets t_j = j/m, j = −m … m, the centre value of the
//! least-squares quartic is Σ_j c_j P_j with c_j = e₀ᵀ(AᵀA)⁻¹Aᵀ, A_jp = t_j^p. The grid extends half a
//! window beyond the spectrum's range on each side (through its power-law extrapolation), so every
//! returned node has its full window.

use crate::error::Result;
use crate::linear::LinearSpectrum;

/// The width of the window in ln k.
pub const WINDOW: f64 = 1.945_910_149_055_313_3; // ln 7
/// Grid points per unit ln k.
const PER_E_FOLD: f64 = 100.0;
/// The degree of the fitted polynomial.
const ORDER: usize = 4;

/// The centre coefficients of the least-squares polynomial of degree [`ORDER`] over 2m + 1 points.
fn coefficients(m: usize) -> Vec<f64> {
    let n = ORDER + 1;
    let t: Vec<f64> = (0..=2 * m)
        .map(|j| (j as f64 - m as f64) / m as f64)
        .collect();
    // Normal matrix AᵀA (moments of t) and the solve of (AᵀA) a = e₀.
    let mut a = vec![vec![0.0; n + 1]; n];
    for (p, row) in a.iter_mut().enumerate() {
        for (q, v) in row.iter_mut().take(n).enumerate() {
            *v = t.iter().map(|&x| x.powi((p + q) as i32)).sum();
        }
        row[n] = if p == 0 { 1.0 } else { 0.0 };
    }
    for c in 0..n {
        let pivot = (c..n)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap_or(c);
        a.swap(c, pivot);
        let pivot_row = a[c].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != c {
                let factor = row[c] / pivot_row[c];
                for (v, p) in row.iter_mut().zip(&pivot_row).skip(c) {
                    *v -= factor * p;
                }
            }
        }
    }
    let sol: Vec<f64> = (0..n).map(|p| a[p][n] / a[p][p]).collect();
    t.iter()
        .map(|&x| sol.iter().rev().fold(0.0, |acc, s| acc * x + s))
        .collect()
}

/// The no-wiggle part of `spectrum` on its own k range by the Savitzky–Golay filter (module docs).
///
/// # Errors
/// As [`LinearSpectrum::from_nodes`].
pub fn savitzky_golay_no_wiggle(spectrum: &LinearSpectrum) -> Result<LinearSpectrum> {
    let step = 1.0 / PER_E_FOLD;
    let m = ((WINDOW / step).ceil() as usize) / 2;
    let c = coefficients(m);
    let (lo, hi) = (spectrum.k_min().ln(), spectrum.k_max().ln());
    let n = ((hi - lo) / step).ceil() as usize + 1;
    let step = (hi - lo) / (n - 1) as f64;
    let samples: Vec<f64> = (0..n + 2 * m)
        .map(|i| spectrum.eval((lo + step * (i as f64 - m as f64)).exp()))
        .collect();
    let k: Vec<f64> = (0..n).map(|i| (lo + step * i as f64).exp()).collect();
    let p: Vec<f64> = (0..n)
        .map(|i| c.iter().zip(&samples[i..]).map(|(a, b)| a * b).sum())
        .collect();
    LinearSpectrum::from_nodes(k, p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filter keeps quartics exactly and its coefficients sum to 1.
    #[test]
    fn the_filter_reproduces_polynomials_of_its_order() {
        let m = 50;
        let c = coefficients(m);
        assert!((c.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        for p in 1..=ORDER {
            let moment: f64 = c
                .iter()
                .enumerate()
                .map(|(j, cj)| cj * ((j as f64 - m as f64) / m as f64).powi(p as i32))
                .sum();
            assert!(moment.abs() < 1e-12, "t^{p}: {moment}");
        }
        // A quadratic's centre value, and a sinusoid much shorter than the window is removed.
        let f = |x: f64| 2.0 + 3.0 * x - x * x;
        let v: f64 = (0..=2 * m)
            .map(|j| c[j] * f(0.3 + (j as f64 - m as f64) * 0.01))
            .sum();
        assert!((v - f(0.3)).abs() < 1e-12);
        let s: f64 = (0..=2 * m)
            .map(|j| c[j] * ((j as f64 - m as f64) * 0.5).sin())
            .sum();
        assert!(s.abs() < 0.02, "{s}");
    }
}
