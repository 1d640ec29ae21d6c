//! A spectrum's interpolation rule as a linear map of node values, and its logarithmic slope: what the
//! derivatives of a spectrum whose node values and nodes depend on parameters need.
//!
//! [`LinearSpectrum`] interpolates ln P between its nodes (ln k_i, ln P_i) by the not-a-knot cubic
//! spline in ln k, and continues it beyond the end nodes along the lines fitted to the last
//! [`EXTRAPOLATION_POINTS`](super::EXTRAPOLATION_POINTS) nodes (through the end node, least-squares
//! slope). At fixed nodes both are linear in the node values, so if the ln P_i depend on a parameter
//! θ, ∂ ln P(k)/∂θ is the same rule applied to the ∂ ln P_i/∂θ ([`LinearSpectrum::interpolant`]).
//! Both depend on the nodes only through their differences, so if all nodes move together,
//! ln k_i = ln x_i − ln r(θ) with fixed x_i, ln P(k) is a function of ln k + ln r and at fixed k gains
//! (d ln P/d ln k)(k) ∂ ln r/∂θ ([`LinearSpectrum::log_slope`]):
//!
//! ∂ ln P(k)/∂θ = S(k; ∂ ln P_i/∂θ) + (d ln P/d ln k)(k) ∂ ln r/∂θ.
//!
//! Units: k in h/Mpc.

use super::spline::{least_squares_slope, LogSpline};
use super::{LinearSpectrum, EXTRAPOLATION_POINTS};
use crate::error::{Error, Result};

/// A spectrum's interpolation rule applied to other values v_i at its nodes k_i
/// ([`LinearSpectrum::interpolant`]): v(k) by the same not-a-knot spline in ln k between the nodes,
/// and beyond them the end value continued linearly in ln k with the least-squares slope of the
/// values at the end nodes, in the same regions as [`LinearSpectrum::eval`]. Linear in the v_i.
#[derive(Debug, Clone)]
pub struct NodeInterpolant {
    spline: LogSpline,
    k_range: (f64, f64),
    /// (ln k, v) of the anchor node and the slope dv/d ln k, below and above the nodes.
    low: (f64, f64, f64),
    high: (f64, f64, f64),
}

impl NodeInterpolant {
    /// v at k [h/Mpc]: the spline for k_min ≤ k ≤ k_max, the end lines beyond; NaN unless k > 0.
    pub fn eval(&self, k: f64) -> f64 {
        let line = |(x0, v0, slope): (f64, f64, f64)| v0 + slope * (k.ln() - x0);
        if k.is_nan() || k <= 0.0 {
            f64::NAN
        } else if k < self.k_range.0 {
            line(self.low)
        } else if k > self.k_range.1 {
            line(self.high)
        } else {
            self.spline.eval(k.ln())
        }
    }
}

impl LinearSpectrum {
    /// This spectrum's interpolation rule applied to `values`, one per node ([`NodeInterpolant`],
    /// module docs): applied to ln P_i it gives ln P(k); applied to ∂ ln P_i/∂θ, ∂ ln P(k)/∂θ at
    /// fixed nodes.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] unless there is one value per node.
    pub fn interpolant(&self, values: Vec<f64>) -> Result<NodeInterpolant> {
        let n = self.k.len();
        if values.len() != n {
            return Err(Error::LengthMismatch {
                what: "node values and nodes",
                left: values.len(),
                right: n,
            });
        }
        let m = EXTRAPOLATION_POINTS;
        let x: Vec<f64> = self.k.iter().map(|k| k.ln()).collect();
        let low = (x[0], values[0], least_squares_slope(&x[..m], &values[..m]));
        let high = (
            x[n - 1],
            values[n - 1],
            least_squares_slope(&x[n - m..], &values[n - m..]),
        );
        Ok(NodeInterpolant {
            spline: self.spline.with_values(values),
            k_range: (self.k_min(), self.k_max()),
            low,
            high,
        })
    }

    /// d ln P/d ln k at k [h/Mpc]: the derivative of the interpolant of [`eval`](Self::eval), the
    /// spline's for k_min ≤ k ≤ k_max, the power law's slope beyond; NaN unless k > 0.
    pub fn log_slope(&self, k: f64) -> f64 {
        if k.is_nan() || k <= 0.0 {
            f64::NAN
        } else if k < self.k_min() {
            self.low.slope
        } else if k > self.k_max() {
            self.high.slope
        } else {
            self.spline.derivative(k.ln())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Applied to the spectrum's own ln P_i the rule gives ln P(k), in the tails too; the slope is
    /// the derivative of ln P(k) in ln k; a wrong number of values is refused.
    #[test]
    fn the_rule_on_ln_p_is_the_spectrum_and_the_slope_its_derivative() {
        let p = LinearSpectrum::gm2012_z0();
        let ln_p: Vec<f64> = p.nodes().1.iter().map(|v| v.ln()).collect();
        let s = p.interpolant(ln_p).unwrap();
        for k in [1e-6, 2e-4, 0.01, 0.1234, 1.0, 30.0, 49.9, 500.0] {
            assert!((s.eval(k) - p.eval(k).ln()).abs() < 1e-12, "k = {k}");
            let e = 1e-5;
            let fd = (p.eval(k * (1.0 + e)).ln() - p.eval(k * (1.0 - e)).ln())
                / ((1.0 + e) / (1.0 - e)).ln();
            assert!((p.log_slope(k) - fd).abs() < 1e-6, "k = {k}");
        }
        assert!(s.eval(0.0).is_nan() && p.log_slope(-1.0).is_nan());
        assert!(p.interpolant(vec![0.0; 3]).is_err());
    }
}
