//! Log-spaced wavenumber grids.

use super::{check_positive, invalid};
use crate::error::Result;

/// A grid of `n` logarithmically spaced wavenumbers from `k_min` to `k_max` (both included), in h/Mpc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogGrid {
    /// First wavenumber [h/Mpc].
    pub k_min: f64,
    /// Last wavenumber [h/Mpc].
    pub k_max: f64,
    /// Number of points.
    pub n: usize,
}

impl LogGrid {
    /// The grid `n` log-spaced points from `k_min` to `k_max` [h/Mpc].
    ///
    /// # Errors
    /// [`crate::error::Error::InvalidParameter`] unless 0 < `k_min` < `k_max` < ∞ and `n` ≥ 2.
    pub fn new(k_min: f64, k_max: f64, n: usize) -> Result<Self> {
        check_positive("k_min [h/Mpc]", k_min)?;
        check_positive("k_max [h/Mpc]", k_max)?;
        if k_max <= k_min {
            return Err(invalid("k_max [h/Mpc]", k_max, "must exceed k_min"));
        }
        if n < 2 {
            return Err(invalid("n (grid points)", n as f64, "must be at least 2"));
        }
        Ok(Self { k_min, k_max, n })
    }

    /// The points as a validated [`crate::table::KGrid`] (valid by construction).
    pub fn k_grid(&self) -> crate::table::KGrid {
        crate::table::KGrid::valid(self.points())
    }

    /// The wavenumbers k_i = k_min (k_max/k_min)^(i/(n−1)) [h/Mpc].
    pub fn points(&self) -> Vec<f64> {
        let (a, b) = (self.k_min.ln(), self.k_max.ln());
        let step = (b - a) / (self.n - 1) as f64;
        (0..self.n)
            .map(|i| match i {
                0 => self.k_min,
                _ if i == self.n - 1 => self.k_max,
                _ => (a + step * i as f64).exp(),
            })
            .collect()
    }
}

impl Default for LogGrid {
    /// 1200 points from 1e-4 to 50 h/Mpc, the grid of the embedded CAMB tables.
    fn default() -> Self {
        Self {
            k_min: 1e-4,
            k_max: 50.0,
            n: 1200,
        }
    }
}
