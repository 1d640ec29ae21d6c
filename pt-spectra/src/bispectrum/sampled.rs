//! The linear spectrum (and its no-wiggle part) sampled once per spectrum on a grid uniform in k over
//! the sides a plan can reach, so that every node of the bin and orientation averages looks P up by
//! 4-point Lagrange interpolation without a search, a log or an exp: on the interval
//! [k₀ + ih, k₀ + (i + 1)h] the cubic through the samples s_{i−1} … s_{i+2}, written as
//! s_i + c₁u + c₂u² + c₃u³ in u = (k − k₀)/h − i (one row of four coefficients per interval and
//! spectrum, read at once). The interpolation error is measured when the table is made (at interval
//! midpoints against the spectrum itself) and carried into the error estimates.

use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;

/// At most this many samples; the spacing is at most [`MAX_SPACING`] and an eighth of the lowest k.
const MAX_SAMPLES: usize = 8192;
/// Largest spacing [h/Mpc]: 0.0016 of the BAO period 2π/r_s ≈ 0.06 h/Mpc, so the wiggles are resolved.
const MAX_SPACING: f64 = 1e-4;
/// Every `PROBE_STRIDE`-th interval midpoint is compared with the spectrum itself.
const PROBE_STRIDE: usize = 3;

/// P and P_nw sampled at k₀ + i h, i = 0 … n − 1, as the cubic coefficients of each interval.
#[derive(Debug, Clone)]
pub(crate) struct Sampled {
    pub(super) k0: f64,
    pub(super) inv_h: f64,
    /// Row i − 1 holds the coefficients (s_i, c₁, c₂, c₃) of P, then those of P_nw, on the interval
    /// starting at sample i, i = 1 … n − 3 (one cache line per lookup).
    pub(super) rows: Vec<[f64; 8]>,
    /// Largest relative interpolation error measured (P or P_nw).
    pub(crate) relative_error: f64,
}

impl Sampled {
    /// Samples `spectrum` (and `no_wiggle`, or the spectrum again without IR resummation) over
    /// [k_lo, k_hi] [h/Mpc], 0 < k_lo < k_hi, with two samples of margin on each side.
    pub(crate) fn new(
        spectrum: &LinearSpectrum,
        no_wiggle: Option<&LinearSpectrum>,
        k_lo: f64,
        k_hi: f64,
    ) -> Result<Self> {
        if !(k_lo > 0.0 && k_hi > k_lo && k_hi.is_finite()) {
            return Err(Error::InvalidChoice {
                what: format!("sampled k range [{k_lo}, {k_hi}] h/Mpc"),
                reason: "needs 0 < k_lo < k_hi < ∞".into(),
            });
        }
        let range = k_hi - k_lo;
        // the spacing wanted, widened if the range would need more than MAX_SAMPLES (the measured
        // error then says what that costs)
        let h = MAX_SPACING
            .min(k_lo / 8.0)
            .min(range / 4.0)
            .max(range / (MAX_SAMPLES - 5) as f64);
        let n = (range / h).ceil() as usize + 5;
        // two samples of margin on each side (k₀ may then be ≤ 0, where P is 0: only for a range
        // wider than MAX_SAMPLES eighths of k_lo, and the measured error shows it)
        let k0 = k_lo - 2.0 * h;
        let nodes = |f: &LinearSpectrum| -> Vec<f64> {
            (0..n).map(|i| f.eval(k0 + i as f64 * h)).collect()
        };
        let p = nodes(spectrum);
        let p_nw = no_wiggle.map_or_else(|| p.clone(), nodes);
        let mut table = Self {
            k0,
            inv_h: 1.0 / h,
            rows: (1..n - 2)
                .map(|i| {
                    let (a, b) = (cubic(&p[i - 1..i + 3]), cubic(&p_nw[i - 1..i + 3]));
                    [a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]]
                })
                .collect(),
            relative_error: 0.0,
        };
        let mut worst = 0.0_f64;
        for i in (2..n - 3).step_by(PROBE_STRIDE) {
            let k = k0 + (i as f64 + 0.5) * h;
            let (p, p_nw) = table.eval(k);
            worst = worst.max((p / spectrum.eval(k) - 1.0).abs());
            if let Some(nw) = no_wiggle {
                worst = worst.max((p_nw / nw.eval(k) - 1.0).abs());
            }
        }
        table.relative_error = worst;
        Ok(table)
    }

    /// The last interval's first sample, n − 3 (intervals 1 … n − 3 have rows).
    pub(super) fn last(&self) -> f64 {
        self.rows.len() as f64
    }

    /// (P, P_nw) at k [h/Mpc] inside the sampled range (clamped to its end intervals outside it).
    #[inline]
    pub(crate) fn eval(&self, k: f64) -> (f64, f64) {
        let t = (k - self.k0) * self.inv_h;
        // truncation, not floor: they differ only at t < 0, which the clamp to 1 maps alike
        let i = (t as usize).clamp(1, self.rows.len());
        let u = t - i as f64;
        let c = &self.rows[i - 1];
        (
            c[0] + u * (c[1] + u * (c[2] + u * c[3])),
            c[4] + u * (c[5] + u * (c[6] + u * c[7])),
        )
    }
}

/// The cubic through (−1, s₀), (0, s₁), (1, s₂), (2, s₃) as s₁ + c₁u + c₂u² + c₃u³: (s₁, c₁, c₂, c₃).
fn cubic(s: &[f64]) -> [f64; 4] {
    [
        s[1],
        s[2] - s[0] / 3.0 - s[1] / 2.0 - s[3] / 6.0,
        (s[0] + s[2]) / 2.0 - s[1],
        (s[3] - s[0]) / 6.0 + (s[1] - s[2]) / 2.0,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cubic_is_reproduced_and_the_measured_error_bounds_a_real_spectrum() {
        // a cubic in k is interpolated exactly by 4-point Lagrange
        let k: Vec<f64> = (0..400).map(|i| 0.001 * 1.02_f64.powi(i)).collect();
        let cubic = |k: f64| 1.0 + k + 3.0 * k * k + 2.0 * k * k * k;
        let p =
            LinearSpectrum::from_nodes(k.clone(), k.iter().map(|&k| cubic(k)).collect()).unwrap();
        let table = Sampled::new(&p, None, 0.01, 0.3).unwrap();
        for kk in [0.0101, 0.0777, 0.2999] {
            let (a, b) = table.eval(kk);
            // the spline through the cubic is not exactly the cubic: compare with it, not with `cubic`
            assert!((a / p.eval(kk) - 1.0).abs() < 1e-9 && a == b);
        }
        // the real spectrum: every point within 4× the measured error (measured at a third of the
        // midpoints) and that error small
        let lin = LinearSpectrum::gm2012(0.5).unwrap();
        let table = Sampled::new(&lin, None, 0.005, 0.35).unwrap();
        // 1.9e-6 measured: the table's spline has third-derivative jumps at its knots (CAMB's own
        // interpolation), so the error falls as h³, not h⁴
        assert!(table.relative_error < 5e-6, "{}", table.relative_error);
        for i in 0..2000 {
            let kk = 0.005 + 0.345 * f64::from(i) / 2000.0;
            let e = (table.eval(kk).0 / lin.eval(kk) - 1.0).abs();
            assert!(e <= 4.0 * table.relative_error + 1e-12, "k = {kk}: {e}");
        }
        assert!(Sampled::new(&lin, None, 0.0, 0.3).is_err());
    }
}
