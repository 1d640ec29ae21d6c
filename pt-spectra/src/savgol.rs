//! The no-wiggle spectrum of velocileptors' `REPT` (Chen, Vlah, Castorina & White 2021): a
//! Savitzky–Golay filter of P itself, a quartic least-squares fit over a window ln 7 wide in ln k
//! (about one BAO oscillation from k = 0.01 h/Mpc) evaluated at its centre, on a log-uniform grid.
//!
//! The filter is a fixed convolution: for offsets t_j = j/m, j = −m … m, the centre value of the
//! least-squares quartic is Σ_j c_j P_j with c_j = e₀ᵀ(AᵀA)⁻¹Aᵀ, A_jp = t_j^p. The grid extends half a
//! window beyond the spectrum's range on each side (through its power-law extrapolation), so every
//! returned node has its full window.
//!
//! A leaf module (public as [`crate::ir::savitzky_golay_no_wiggle`]): the loops' basis tensors use
//! the filter on the lattice ([`no_wiggle_samples`]) without importing `ir`, which imports the loops.

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

/// The same filter applied to `samples` on a grid uniform in ln k with spacing `step` (the loop
/// lattice): linear in the samples, so the no-wiggle part of a spectrum Σ c_a φ_a on a basis is
/// Σ c_a (filtered φ_a). It filters at the resolution of [`savitzky_golay_no_wiggle`] (the window
/// in points matters: one ln 7 wide at a coarser step leaks the BAO differently): a grid coarser
/// than 1/[`PER_E_FOLD`] is first refined r = round(step · PER_E_FOLD) times by four-point Lagrange
/// interpolation, filtered, and read back at its points. The m points at either end of the refined
/// grid, without a full window (m = ⌈ln 7 / step⌉ / 2), are kept unfiltered (on the loop lattice
/// q < 2.7e-5 and q > 370 h/Mpc, far from the BAO).
pub(crate) fn no_wiggle_samples(samples: &[f64], step: f64) -> Vec<f64> {
    let filter = LatticeFilter::new(step);
    let n = samples.len();
    (0..n)
        .map(|j| {
            let mut v = 0.0;
            filter.taps(n, j, |i, w| v += w * samples[i]);
            v
        })
        .collect()
}

/// The value of [`no_wiggle_samples`] at lattice index `j` of a grid of `n` samples spaced `step`,
/// as weights over the samples: (first index, weights), Σ_i w_i P_{first + i}. For a no-wiggle
/// spectrum at a few points from the samples themselves, not their projection on a basis.
pub(crate) fn no_wiggle_weights(n: usize, step: f64, j: usize) -> (usize, Vec<f64>) {
    let mut taps = Vec::new();
    LatticeFilter::new(step).taps(n, j, |i, w| taps.push((i, w)));
    let first = taps.iter().map(|t| t.0).min().unwrap_or(j);
    let last = taps.iter().map(|t| t.0).max().unwrap_or(j);
    let mut w = vec![0.0; last + 1 - first];
    for (i, v) in taps {
        w[i - first] += v;
    }
    (first, w)
}

/// The filter on a lattice (module docs, [`no_wiggle_samples`]): the refinement r, the half-width m
/// of the window on the refined grid and its coefficients.
struct LatticeFilter {
    r: usize,
    m: usize,
    coefficients: Vec<f64>,
}

impl LatticeFilter {
    fn new(step: f64) -> Self {
        let r = ((step * PER_E_FOLD).round() as usize).max(1);
        let m = ((WINDOW * r as f64 / step).ceil() as usize) / 2;
        Self {
            r,
            m,
            coefficients: coefficients(m),
        }
    }

    /// Calls `tap(i, w)` for each sample i of a lattice of `n` and its weight w in the filtered value
    /// at index `j` (the refined grid's points interpolated from the samples; the sample itself where
    /// the window does not fit).
    fn taps(&self, n: usize, j: usize, mut tap: impl FnMut(usize, f64)) {
        let (r, m) = (self.r, self.m);
        let (i, len) = (j * r, (n.max(1) - 1) * r + 1);
        if n < 4 || i < m || i + m >= len {
            return tap(j, 1.0);
        }
        for (t, c) in self.coefficients.iter().enumerate() {
            let u = i - m + t;
            let (k, frac) = (u / r, (u % r) as f64 / r as f64);
            if frac == 0.0 {
                tap(k, *c);
            } else {
                let b = k.saturating_sub(1).min(n - 4);
                let l = crate::integrate::lagrange4(k as f64 + frac - b as f64);
                for (s, ls) in l.iter().enumerate() {
                    tap(b + s, c * ls);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On the same grid, the lattice filter equals the filter of the spectrum's table away from the
    /// ends (the table's filter samples the spectrum at the same ln k when the grids coincide).
    #[test]
    fn the_lattice_filter_matches_the_table_filter_on_a_common_grid() {
        let k: Vec<f64> = (0..=600).map(|i| (-9.0 + 0.01 * i as f64).exp()).collect();
        let p: Vec<f64> = k
            .iter()
            .map(|&k| 1e4 * k / (1.0 + (k / 0.02f64).powi(3)) * (1.0 + 0.05 * (k * 100.0).sin()))
            .collect();
        let spectrum = LinearSpectrum::from_nodes(k.clone(), p.clone()).unwrap();
        let table = savitzky_golay_no_wiggle(&spectrum).unwrap();
        let lattice = no_wiggle_samples(&p, 0.01);
        let m = 97;
        assert_eq!(&lattice[..m], &p[..m]);
        for i in m..=600 - m {
            let t = table.eval(k[i]);
            assert!(
                (lattice[i] / t - 1.0).abs() < 1e-12,
                "{i}: {} {t}",
                lattice[i]
            );
        }
        // On a grid twice as coarse the filter works at the table's resolution: equal to the
        // interpolation error of the refined grid (P and its wiggle are smooth on 0.02 in ln k).
        let coarse: Vec<f64> = p.iter().step_by(2).copied().collect();
        let filtered = no_wiggle_samples(&coarse, 0.02);
        for j in 49..=300 - 49 {
            let t = table.eval(k[2 * j]);
            assert!(
                (filtered[j] / t - 1.0).abs() < 1e-6,
                "{j}: {} {t}",
                filtered[j]
            );
        }
        // The weights of single points give the same values, at the ends too.
        for (samples, step, filtered) in [(&p, 0.01, &lattice), (&coarse, 0.02, &filtered)] {
            for j in [
                0,
                10,
                48,
                49,
                97,
                98,
                150,
                samples.len() - 50,
                samples.len() - 1,
            ] {
                let (first, w) = no_wiggle_weights(samples.len(), step, j);
                let v = crate::simd::dot(&w, &samples[first..first + w.len()]);
                assert!(
                    (v / filtered[j] - 1.0).abs() < 1e-13,
                    "{step} {j}: {v} {}",
                    filtered[j]
                );
            }
        }
    }

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
